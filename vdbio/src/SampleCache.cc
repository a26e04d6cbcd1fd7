/// @file   SampleCache.cc
#include "ghostfx/vdbio/SampleCache.h"

#include "ghostfx/vdbio/AtomicFile.h"

#include <ghostfx/sph/Exceptions.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <tuple>
#include <vector>

namespace ghostfx {
namespace vdbio {

namespace {
constexpr char MAGIC[8] = {'G', 'F', 'X', 'S', 'M', 'P', '0', '1'};
} // namespace

SampleCache::SampleCache(std::string folder, std::uint64_t maxBytes)
    : mFolder(std::move(folder))
    , mMaxBytes(maxBytes)
{
    try {
        ensureWritableDirectory(mFolder);
    } catch (const IoError& e) {
        // "output folder 'X': why" -> "sample cache folder 'X': why"
        const std::string what = e.what();
        const std::size_t quote = what.find('\'');
        throw IoError("sample cache folder "
                      + (quote == std::string::npos ? what : what.substr(quote)));
    }
}

std::string SampleCache::pathOf(std::uint64_t key) const
{
    char name[32];
    std::snprintf(name, sizeof name, "%016" PRIx64 ".gfxsamples", key);
    return (std::filesystem::path(mFolder) / name).string();
}

std::optional<sph::SampleSet> SampleCache::load(std::uint64_t key)
{
    std::ifstream in(pathOf(key), std::ios::binary);
    if (!in) return std::nullopt;
    char magic[8];
    std::uint32_t realSize = 0;
    std::uint64_t storedKey = 0, count = 0;
    in.read(magic, 8);
    in.read(reinterpret_cast<char*>(&realSize), sizeof realSize);
    in.read(reinterpret_cast<char*>(&storedKey), sizeof storedKey);
    in.read(reinterpret_cast<char*>(&count), sizeof count);
    if (!in || std::memcmp(magic, MAGIC, 8) != 0 || realSize != sizeof(sph::Real)
        || storedKey != key || count > (std::uint64_t(1) << 40)) {
        return std::nullopt;
    }
    sph::SampleSet samples;
    samples.positions.resize(std::size_t(count));
    samples.onSurface.resize(std::size_t(count));
    in.read(reinterpret_cast<char*>(samples.positions.data()),
            std::streamsize(count * sizeof(sph::Vec3)));
    in.read(reinterpret_cast<char*>(samples.onSurface.data()), std::streamsize(count));
    // Nothing may follow: a longer file is not one this version wrote.
    if (!in || in.peek() != std::char_traits<char>::eof()) return std::nullopt;
    in.close();
    if (mMaxBytes > 0) {
        // Used now: the limit removes the least recently used first. Best effort.
        std::error_code ec;
        std::filesystem::last_write_time(pathOf(key), std::filesystem::file_time_type::clock::now(),
                                         ec);
    }
    ++mHits;
    return samples;
}

void SampleCache::store(std::uint64_t key, const sph::SampleSet& samples)
{
    static_assert(sizeof(sph::Vec3) == 3 * sizeof(sph::Real), "Vec3 is three packed Reals");
    const std::string path = pathOf(key);
    try {
        writeAtomically(path, [&](const std::string& tmp) {
            std::ofstream out(tmp, std::ios::binary);
            const std::uint32_t realSize = sizeof(sph::Real);
            const std::uint64_t count = samples.size();
            out.write(MAGIC, 8);
            out.write(reinterpret_cast<const char*>(&realSize), sizeof realSize);
            out.write(reinterpret_cast<const char*>(&key), sizeof key);
            out.write(reinterpret_cast<const char*>(&count), sizeof count);
            out.write(reinterpret_cast<const char*>(samples.positions.data()),
                      std::streamsize(count * sizeof(sph::Vec3)));
            out.write(reinterpret_cast<const char*>(samples.onSurface.data()),
                      std::streamsize(count));
            out.close();
            if (!out) throw IoError(msg("sample cache file '", path, "': write failed"));
        });
    } catch (const Error& e) {
        std::lock_guard<std::mutex> lock(mMutex);
        if (mFailures++ == 0) mFirstFailure = e.what();
        return;
    }
    ++mStored;
    if (mMaxBytes > 0) trim(path);
}

void SampleCache::trim(const std::string& keep)
{
    namespace fs = std::filesystem;
    std::lock_guard<std::mutex> lock(mMutex);
    // Other processes may add or remove files meanwhile: every step is best effort.
    std::vector<std::tuple<fs::file_time_type, std::uint64_t, fs::path>> files;
    std::uint64_t total = 0;
    std::error_code ec;
    for (fs::directory_iterator it(mFolder, ec), end; !ec && it != end; it.increment(ec)) {
        const fs::path& p = it->path();
        std::error_code e1, e2;
        if (p.extension() != ".gfxsamples" || !it->is_regular_file(e1)) continue;
        const std::uint64_t size = it->file_size(e1);
        const fs::file_time_type time = it->last_write_time(e2);
        if (e1 || e2) continue;
        total += size;
        files.emplace_back(time, size, p);
    }
    if (total <= mMaxBytes) return;
    std::sort(files.begin(), files.end()); // oldest first
    for (const auto& [time, size, p] : files) {
        if (total <= mMaxBytes) break;
        if (p == fs::path(keep)) continue;
        std::error_code e;
        if (fs::remove(p, e)) ++mEvicted;
        total -= size; // gone, by this process or another
    }
}

std::string SampleCache::firstFailure() const
{
    std::lock_guard<std::mutex> lock(mMutex);
    return mFirstFailure;
}

} // namespace vdbio
} // namespace ghostfx
