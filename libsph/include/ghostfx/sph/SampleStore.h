/// @file   SampleStore.h
/// @brief  Sampled shapes kept from an earlier run: a scene run again (another wedge of a study,
///         a shot re-run after a stiffness tweak) takes its unchanged solids' and liquid bodies'
///         samples from the store instead of sampling them again.
/// @details The store is keyed by sampleKey(): everything sampleVolume() reads (every value,
///          tile and the transform of the level set, every PoissonSettings field),
///          SAMPLER_VERSION and the build (compiler and instruction set, whose rounding the
///          samples' last bits follow). Samples from the store are the ones the sampler would make, bit
///          for bit, so a run gives the same results with or without one. libsph opens no
///          files: vdbio::SampleCache is the store on disk (a folder of files).
#pragma once

#include "ghostfx/sph/LevelSet.h"
#include "ghostfx/sph/PoissonSampler.h"

#include <cstdint>
#include <optional>

namespace ghostfx {
namespace sph {

/// Raise when a change to PoissonDiskSampler changes what sampleVolume() returns for the same
/// inputs: stored samples of another version are then never used.
constexpr std::uint32_t SAMPLER_VERSION = 3;

class SampleStore
{
public:
    virtual ~SampleStore() = default;
    /// The samples stored under `key`, or nothing (none stored, or unreadable).
    virtual std::optional<SampleSet> load(std::uint64_t key) = 0;
    /// Keep `samples` under `key` for later runs.
    virtual void store(std::uint64_t key, const SampleSet& samples) = 0;
};

/// The key of `PoissonDiskSampler(settings).sampleVolume(shape)` (64-bit FNV-1a over the
/// level set's contents, the settings, SAMPLER_VERSION and the build).
std::uint64_t sampleKey(const LevelSet& shape, const PoissonSettings& settings);

/// `PoissonDiskSampler(settings).sampleVolume(shape)`, loaded from `store` when it holds the
/// samples and stored there when it does not; without a store, sampled.
SampleSet sampleVolumeStored(const PoissonSettings& settings, const LevelSet& shape,
                             SampleStore* store);

} // namespace sph
} // namespace ghostfx
