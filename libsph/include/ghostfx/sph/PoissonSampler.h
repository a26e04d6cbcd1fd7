/// @file   PoissonSampler.h
/// @brief  Poisson-disk sampling that fits level-set boundaries: surface sampling, interior
///         sampling, relaxation and seeded sampling of [SB12] Sec. 4.5.
/// @details
///   - Surface sampling, [SB12] Algorithm 1: in every grid cell the zero level set crosses,
///     up to t random points are projected to the surface until one is at least r from every
///     sample; from it a walk continues with steps of e r along random tangent directions.
///   - Interior sampling, [SB12] Sec. 4.5.2: Bridson's fast Poisson-disk sampling [Bridson
///     2007] seeded with the existing samples, rejecting candidates outside the level set and,
///     for solids, deeper than a band (`bandDepth`) below the surface.
///   - Relaxation, [SB12] Algorithm 2: each sample in turn tries t candidates at decreasing
///     distance r (t - i) / t and moves to the one farthest from its neighbours within 2r;
///     surface samples stay on the surface, interior candidates outside are projected back.
///   - Packing (SamplePacking.cc; the volume relaxation with `volumeRelaxation = Packing`):
///     [SB12] Algorithm 2's goal, "to reduce noise in the SPH density by optimizing sample
///     locations", reached by moving every sample at once down the gradient of its SPH number
///     density, never closer than r to another sample; eight such steps leave about half the
///     interior density noise of Algorithm 2's 30 sweeps in about an eighth of their time
///     (the 107k bench sphere's whole pipeline: 4.9 s -> 1.6 s on 2 threads;
///     bench/history/diary-2026-11.md, "Sampler: SPH packing as the volume relaxation").
///     Algorithm 2 stays the surface relaxation and the default volume relaxation.
///   - Seeded sampling (air layers, emission, [SB12] Sec. 4.5.2 with t = 8): grow samples from
///     existing particles inside a region given by a predicate, keeping r from other particles.
///   With r = 0.92 h ([SB12] Sec. 4.6) the SPH density of the result is close to the rest
///   density; `massForRestDensity` (SphDensity.h) then scales the mass so it averages exactly.
///
///   Every result is a deterministic function of the inputs and the seed, at any thread count.
///   Algorithm 1 and Bridson's growth are sequential by nature (each sample depends on all
///   earlier ones), so they run tile by tile: cubes of 16r coloured by the parity of their
///   coordinates, the tiles of one colour in parallel, the colours in order (Bridson's growth
///   goes on into a neighbour's tile from samples it placed there, so every sample is grown from
///   once, as in one pass). The packing and Algorithm 2 run in parallel by coloured blocks too;
///   seeded sampling stays sequential (air layers and emission are thin).
#pragma once

#include "ghostfx/sph/LevelSet.h"
#include "ghostfx/sph/Types.h"

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace ghostfx {
namespace sph {

/// Settings of the sampler, with the defaults of [SB12] Sec. 4.5 - 4.6.
struct PoissonSettings
{
    /// [SB12] Sec. 4.6: Poisson radius as a fraction of the particle spacing.
    static constexpr Real SB12_RADIUS_FACTOR = Real(0.92);
    /// [SB12] Sec. 4.5.2: attempts per sample for air layers and emission, where speed matters.
    static constexpr int SB12_SEEDED_ATTEMPTS = 8;

    Real radius = Real(0);          ///< Poisson-disk radius r (m); no two samples closer
    int surfaceAttempts = 30;       ///< t of Algorithm 1 (per cell and per walk step)
    Real surfaceStep = Real(1.085); ///< e of Algorithm 1: walk step e r
    int volumeAttempts = 30;        ///< Bridson's t; [SB12] uses 8 for air and emission
    int relaxAttempts = 50;         ///< t of Algorithm 2
    /// How the volume relaxation (after the interior sampling) moves the samples.
    enum class Relaxation : std::uint8_t {
        /// SPH packing: `packingIterations` Jacobi steps down the gradient of each sample's
        /// number density (SamplePacking.cc).
        Packing,
        /// [SB12] Algorithm 2: `volumeRelaxSweeps` sweeps of `relaxAttempts` candidates.
        Sb12
    };

    int surfaceRelaxSweeps = 5; ///< k of Algorithm 2 for the surface
    int volumeRelaxSweeps = 30; ///< k of Algorithm 2 for the volume (Relaxation::Sb12)
    Relaxation volumeRelaxation = Relaxation::Sb12; ///< the volume relaxation's method
    int packingIterations = 8; ///< steps of the packing (Relaxation::Packing); 0: none
    /// Sample only down to this depth below the surface (m): solids need one kernel radius
    /// ([SB12] Sec. 4.5). Infinity samples the whole interior.
    Real bandDepth = std::numeric_limits<Real>::infinity();
    std::uint64_t seed = 0; ///< random seed: same seed, same samples
    /// sampleVolume fills the interior deeper than 2r with copies of a periodic tile that was
    /// relaxed once ([SB12] Algorithms 1 and 2 run only between the surface and that depth):
    /// about twice as fast for large bodies, but the whole interior inherits the one tile's
    /// packing density, which differs from the layer near the surface by up to about 2 %
    /// (bench/history/diary-2026-11.md); off by default. See sampleVolume.
    bool tiledInterior = false;
    /// Refuse (SamplingError) to create more samples than this: a guard against a spacing far
    /// too small for the shape.
    std::size_t maxSamples = 100'000'000;

    /// Settings for particle spacing h (m): r = 0.92 h.
    static PoissonSettings forSpacing(Real spacing);

    /// Throw ValueError naming the first field out of range.
    void validate() const;
};

/// Samples and which of them lie on the surface.
struct SampleSet
{
    std::vector<Vec3> positions;         ///< (m)
    std::vector<std::uint8_t> onSurface; ///< 1 for a surface sample, 0 for an interior one

    std::size_t size() const { return positions.size(); }
    std::size_t surfaceCount() const;
};

class PoissonDiskSampler
{
public:
    explicit PoissonDiskSampler(const PoissonSettings& settings);

    const PoissonSettings& settings() const { return mSettings; }

    /// The full pipeline of [SB12] Sec. 4.5 for initial liquid and solids: surface sampling,
    /// surface relaxation, interior sampling (limited to `bandDepth`), volume relaxation.
    /// With `tiledInterior` the interior deeper than 2r comes from copies of a
    /// small periodic tile, itself sampled and relaxed with the same Bridson growth and
    /// Algorithm 2 (periodic distances); growth and relaxation then run only in the layer
    /// between the surface and that depth, with the tile points held still. The result keeps
    /// the Poisson radius everywhere (the tile is periodic, the layer grows around it) and the
    /// relaxed density spread, at a cost that grows with the surface, not the volume
    /// (bench/history/diary-2026-11.md, "Poisson-disk sampling rate").
    /// Throws SamplingError if the level set has no zero crossing.
    SampleSet sampleVolume(const LevelSet& shape) const;

    /// Algorithm 1 alone.
    SampleSet sampleSurface(const LevelSet& shape) const;
    /// Interior sampling seeded by `samples` (appends interior samples).
    void sampleInterior(SampleSet& samples, const LevelSet& shape) const;
    /// Algorithm 2 over every sample, `sweeps` times; `pass` decorrelates the random streams
    /// of separate relaxations.
    void relax(SampleSet& samples, const LevelSet& shape, int sweeps, int pass = 0) const;
    /// The volume relaxation that sampleVolume runs after the interior sampling: packing or
    /// Algorithm 2, as `volumeRelaxation` says.
    void relaxVolume(SampleSet& samples, const LevelSet& shape) const;
    /// SPH packing of every sample, `iterations` times (SamplePacking.cc).
    void pack(SampleSet& samples, const LevelSet& shape, int iterations) const;

    /// Seeded sampling, [SB12] Sec. 4.5.2: new samples grown from `seeds` (existing particles)
    /// in annuli [r, 2r], kept where `accept(x)` is true, at least r from every seed, every
    /// obstacle and every other new sample. Attempts per seed: `volumeAttempts` (set it to
    /// SB12_SEEDED_ATTEMPTS = 8 for air and emission, as [SB12] does).
    /// @param bounds  a box that contains every accepted point (m); sizes the search grid
    /// @param where   optional cheap part of `accept` (a point it rejects, `accept` would
    ///                reject too), tested before the distance test: the samples are the same,
    ///                found with fewer searches where many candidates fall outside it
    /// @return the new samples only
    std::vector<Vec3> sampleFromSeeds(const std::vector<Vec3>& seeds,
                                      const std::vector<Vec3>& obstacles,
                                      const std::function<bool(const Vec3&)>& accept,
                                      const Aabb& bounds,
                                      const std::function<bool(const Vec3&)>& where = {}) const;

private:
    SampleSet sampleVolumeTiled(const LevelSet& shape) const;
    /// Bridson growth from the samples with seeds[i] (all when empty); the rest are obstacles.
    void growInterior(SampleSet& samples, const LevelSet& shape,
                      const std::vector<std::uint8_t>& seeds) const;
    /// Algorithm 2 for the samples with movable[i] (all when empty); the rest hold still.
    void relaxSome(SampleSet& samples, const LevelSet& shape, int sweeps, int pass,
                   const std::vector<std::uint8_t>& movable) const;
    /// The volume relaxation for the samples with movable[i] (all when empty).
    void relaxVolumeSome(SampleSet& samples, const LevelSet& shape,
                         const std::vector<std::uint8_t>& movable) const;
    /// Packing for the samples with movable[i] (all when empty); the rest hold still.
    void packSome(SampleSet& samples, const LevelSet& shape, int iterations,
                  const std::vector<std::uint8_t>& movable) const;
    /// A point set in [0, side)^3 with the Poisson radius across its periodic faces, relaxed.
    std::vector<Vec3> periodicTile(Real side) const;

    PoissonSettings mSettings;
};

} // namespace sph
} // namespace ghostfx
