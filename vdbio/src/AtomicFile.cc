/// @file   AtomicFile.cc
#include <ghostfx/vdbio/AtomicFile.h>

#include <ghostfx/sph/Exceptions.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace ghostfx {
namespace vdbio {

namespace fs = std::filesystem;

namespace {

/// Below this many free bytes a failed write is taken to have met a full device (libraries
/// such as HDF5 and OpenVDB do not always leave errno at ENOSPC).
constexpr std::uintmax_t FULL_DEVICE_BYTES = 1 << 20;

/// ": the device holding 'folder' is full (...)" when a write into `folder` that failed with
/// `savedErrno` and the message `what` met a full device or quota, else "".
std::string fullDeviceNote(const fs::path& folder, int savedErrno, const std::string& what)
{
    std::error_code ec;
    const fs::space_info space = fs::space(folder.empty() ? fs::path(".") : folder, ec);
    const bool full = savedErrno == ENOSPC || savedErrno == EDQUOT
                      || (!ec && space.free < FULL_DEVICE_BYTES);
    if (!full) return "";
    const std::string reason = std::strerror(savedErrno == EDQUOT ? EDQUOT : ENOSPC);
    std::string detail = what.find(reason) == std::string::npos ? reason : std::string();
    if (!ec) detail += msg(detail.empty() ? "" : ", ", space.free, " bytes free");
    return msg(": the device holding '", folder.empty() ? "." : folder.string(), "' is full",
               detail.empty() ? std::string() : " (" + detail + ")",
               "; nothing of this file was kept");
}

} // namespace

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    // Unique per process and call, in the target's folder so the rename never crosses devices.
    static std::atomic<unsigned> counter{0};
    const fs::path target(path);
    const fs::path tmp = target.parent_path()
                         / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid())
                            + "_" + std::to_string(counter++));
    errno = 0;
    try {
        write(tmp.string());
    } catch (const std::exception& e) {
        // Asked while the temporary still holds what was written.
        const std::string full = fullDeviceNote(target.parent_path(), errno, e.what());
        std::error_code ec;
        fs::remove(tmp, ec);
        if (full.empty()) throw;
        throw IoError(msg(e.what(), full));
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

void writeTextFile(const std::string& path, const std::string& text, const std::string& what)
{
    writeAtomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) {
            throw IoError(msg(what, " '", path, "': write failed (",
                              errno != 0 ? std::strerror(errno) : "the stream failed", ")"));
        }
    });
}

std::optional<std::string> readTextFile(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string lastLineOf(const std::string& path)
{
    std::ifstream in(path);
    std::string line, last;
    while (std::getline(in, line)) {
        if (!line.empty()) last = line;
    }
    return last;
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
