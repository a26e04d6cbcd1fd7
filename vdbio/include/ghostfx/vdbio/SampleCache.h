/// @file   SampleCache.h
/// @brief  A folder of sampled shapes (sph::SampleStore on disk), for `ghostfx run
///         --sample-cache DIR` and $GHOSTFX_SAMPLE_CACHE.
/// @details One file per key, `<16 hex digits>.gfxsamples`: an 8-byte magic "GFXSMP01", the
///          size of Real (4 or 8), the key, the sample count, then the positions (3 Reals each)
///          and the surface flags (one byte each), little-endian as written. A file that does
///          not match (another precision, a short or damaged file) is not used and is written
///          again. Files are written atomically, so runs sharing a folder (a study's cases on
///          a farm) never read half a file; the folder can be deleted at any time.
///          With a size limit (the per-user default folder has one, cmd/LiquidScene.h), the
///          files least recently used (written or loaded: a load touches its file's time) are
///          removed after each store until the folder's files fit.
#pragma once

#include <ghostfx/sph/SampleStore.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

namespace ghostfx {
namespace vdbio {

class SampleCache : public sph::SampleStore
{
public:
    /// Creates `folder` if needed; IoError naming it when it cannot be written. `maxBytes`:
    /// the most the folder's .gfxsamples files may hold together (0: no limit).
    explicit SampleCache(std::string folder, std::uint64_t maxBytes = 0);

    std::optional<sph::SampleSet> load(std::uint64_t key) override;
    /// Best effort: a file that cannot be written (a full disk, a folder gone) is counted in
    /// failures() and the run goes on; the cache only saves time.
    void store(std::uint64_t key, const sph::SampleSet& samples) override;

    const std::string& folder() const { return mFolder; }
    std::uint64_t maxBytes() const { return mMaxBytes; }
    std::string pathOf(std::uint64_t key) const;
    /// Shapes loaded, and shapes sampled and stored, so far.
    std::uint64_t hits() const { return mHits; }
    std::uint64_t stored() const { return mStored; }
    /// Shapes that could not be kept, and why the first could not.
    std::uint64_t failures() const { return mFailures; }
    std::string firstFailure() const;
    /// Files removed to keep the folder within maxBytes().
    std::uint64_t evicted() const { return mEvicted; }

private:
    /// Removes the least recently used files (never `keep`) until the rest fit maxBytes().
    void trim(const std::string& keep);

    std::string mFolder;
    std::uint64_t mMaxBytes = 0;
    std::atomic<std::uint64_t> mHits{0}, mStored{0}, mFailures{0}, mEvicted{0};
    mutable std::mutex mMutex;
    std::string mFirstFailure;
};

} // namespace vdbio
} // namespace ghostfx
