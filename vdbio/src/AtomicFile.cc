/// @file   AtomicFile.cc
#include <ghostfx/vdbio/AtomicFile.h>

#include <ghostfx/sph/Exceptions.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace ghostfx {
namespace vdbio {

namespace fs = std::filesystem;

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    // Unique per process and call, in the target's folder so the rename never crosses devices.
    static std::atomic<unsigned> counter{0};
    const fs::path target(path);
    const fs::path tmp = target.parent_path()
                         / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid())
                            + "_" + std::to_string(counter++));
    try {
        write(tmp.string());
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
        const std::string reason = ec.message();
        fs::remove(tmp, ec);
        throw IoError(msg("'", path, "': cannot replace the file (", reason, ")"));
    }
}

void ensureWritableDirectory(const std::string& dir)
{
    const fs::path folder(dir.empty() ? "." : dir);
    std::error_code ec;
    if (fs::exists(folder, ec) && !fs::is_directory(folder, ec)) {
        throw IoError(msg("output folder '", dir, "': exists and is not a folder"));
    }
    fs::create_directories(folder, ec);
    if (ec) throw IoError(msg("output folder '", dir, "': cannot create it (", ec.message(), ")"));
    if (::access(folder.c_str(), W_OK | X_OK) != 0) {
        throw IoError(msg("output folder '", dir, "': not writable (", std::strerror(errno), ")"));
    }
}

bool hasFrameToken(const std::string& pattern) { return pattern.find("$F") != std::string::npos; }

std::string expandFramePattern(const std::string& pattern, int frame)
{
    std::string out;
    for (std::size_t i = 0; i < pattern.size(); ++i) {
        if (pattern.compare(i, 2, "$F") != 0) {
            out += pattern[i];
            continue;
        }
        int width = 0;
        if (i + 2 < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[i + 2]))) {
            width = pattern[i + 2] - '0';
            ++i;
        }
        ++i;
        char buffer[32];
        std::snprintf(buffer, sizeof(buffer), "%0*d", width, frame);
        out += buffer;
    }
    return out;
}

std::string extensionOf(const std::string& path)
{
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

} // namespace vdbio
} // namespace ghostfx
