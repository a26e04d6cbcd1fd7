/// @file   AirResampling.h
/// @brief  One resampling of the ghost air layer ([SB12] Sec. 4.3, Algorithm 3 line 1) in the
///         blocks of some resampling phases: keep the air that still belongs, grow new air from
///         the free surface, and give the region's air the weights it fades towards.
/// @details Resampling runs right after the step's neighbour search and reuses it: the grid of
///          liquid and air answers the nearest-body and inside-the-liquid questions, and the
///          liquid particles' lists give each one's liquid-and-solid indicator. New air grows
///          only from the particles near the free surface (and the kept air): growth from a
///          particle deeper than 2r lands inside the liquid and is refused anyway, so seeding
///          from the whole body would spend most of the resampling on rejected candidates.
///          New air starts at weight 0 and is appended after the lists were built; it takes part
///          in the sums from the next step on.
///
///          The layer is resampled region by region: space is cut into blocks four kernel radii
///          wide, each block belongs to one of `airResampleSteps` phases (AirRegion), and step
///          s resamples the blocks of phase s mod airResampleSteps. Every part of the layer is
///          still resampled every airResampleSteps steps ([SB12] Sec. 4.3), but each step does
///          a tenth of the work, so no step is much slower than the others. DFSPH's steps are
///          several of [SB12]'s long, so a DFSPH step resamples as many consecutive phases as
///          [SB12]'s steps it spans (GhostSettings::airResampleSpan).
///
///          Internal to libghost: GhostSolver::resampleAir (GhostAir.cc) gathers the inputs.
#pragma once

#include <ghostfx/ghost/GhostSettings.h>
#include <ghostfx/sph/BoundaryBlock.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/NeighborLists.h>
#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/ParticleExchange.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/RigidMotion.h>
#include <ghostfx/sph/SolverState.h>
#include <ghostfx/sph/Types.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace ghostfx {
namespace ghost {
namespace detail {

/// The region of `count` consecutive resampling phases from `phase` on: blocks of side 4R
/// whose coordinates (i, j, k) give (i + 3 j + 5 k) mod N in phase, ..., phase + count - 1
/// (mod N). With N = 10 no two blocks that touch (even at a corner) share a phase, and the
/// phases take turns evenly through space.
class AirRegion
{
public:
    using Real = sph::Real;
    using Vec3 = sph::Vec3;

    /// @param supportRadius  kernel radius R (m); a block is 4R wide
    /// @param phases         number of phases N (GhostSettings::airResampleSteps)
    /// @param phase          the first phase of the region, or < 0: everywhere
    /// @param count          number of consecutive phases in the region
    AirRegion(Real supportRadius, int phases, int phase, int count)
        : mBlock(Real(4) * supportRadius)
        , mInvBlock(Real(1) / mBlock)
        , mPhases(phases)
        , mPhase(phase)
    {
        // Whether the block of weighted sum c0 + d is in the region, for c0 mod N in [0, N)
        // and the offsets d = i + 3 j + 5 k in [-9, 9] of the blocks next to it: a table
        // indexed by (c0 mod N) + d + 9, so a neighbour's test takes no division.
        mInRegion.resize(std::size_t(phases) + 2 * MAX_OFFSET);
        for (std::size_t t = 0; t < mInRegion.size(); ++t) {
            const int p = ((int(t) - MAX_OFFSET) % phases + phases) % phases;
            mInRegion[t] = phase < 0 || (p - phase + phases) % phases < count;
        }
    }

    bool everywhere() const { return mPhase < 0; }
    /// The largest margin near() takes: half a block (m).
    Real largestMargin() const { return Real(0.5) * mBlock; }

    int phaseOf(const Vec3& x) const
    {
        const std::int64_t c = block(x[0]) + 3 * block(x[1]) + 5 * block(x[2]);
        return int(((c % mPhases) + mPhases) % mPhases);
    }
    bool contains(const Vec3& x) const { return mPhase < 0 || mInRegion[phaseOf(x) + MAX_OFFSET]; }
    /// Whether x lies within `margin` (m, at most half a block) of the region: the blocks the
    /// box x +- margin touches are the own block and, per axis, the neighbour on the side where
    /// x is closer than the margin to the face.
    bool near(const Vec3& x, Real margin) const
    {
        if (mPhase < 0) return true;
        std::int64_t base = 0;
        int lo[3], hi[3];
        const int weight[3] = {1, 3, 5};
        for (int a = 0; a < 3; ++a) {
            const Real u = x[a] * mInvBlock;
            const Real c = std::floor(u);
            base += weight[a] * std::int64_t(c);
            const Real f = u - c, m = margin * mInvBlock;
            lo[a] = f < m ? -1 : 0;
            hi[a] = f > Real(1) - m ? 1 : 0;
        }
        const std::uint8_t* in =
            mInRegion.data() + ((base % mPhases) + mPhases) % mPhases + MAX_OFFSET;
        for (int i = lo[0]; i <= hi[0]; ++i) {
            for (int j = lo[1]; j <= hi[1]; ++j) {
                for (int k = lo[2]; k <= hi[2]; ++k) {
                    if (in[i + 3 * j + 5 * k]) return true;
                }
            }
        }
        return false;
    }

private:
    /// The largest |i + 3 j + 5 k| of a neighbouring block.
    static constexpr int MAX_OFFSET = 9;
    std::int64_t block(Real v) const { return std::int64_t(std::floor(v * mInvBlock)); }
    Real mBlock, mInvBlock; ///< block side (m) and its inverse
    int mPhases, mPhase;
    std::vector<std::uint8_t> mInRegion; ///< see the constructor
};

/// A block of ghost solid particles as the resampling reads it.
struct AirSolidBlock
{
    const sph::BoundaryBlock& block; ///< the particles and, once sorted, their grid
    const sph::NeighborLists& lists; ///< this step: liquid particle -> block particles
};

/// The solver's state one resampling reads and writes, as the step's neighbour search left it.
struct AirResamplingInputs
{
    const GhostSettings& settings;
    const sph::CubicSplineKernel& kernel;
    sph::ParticleSet& particles;          ///< liquid and ghost air; new air is appended
    const sph::NeighborGrid& grid;        ///< over `particles`, for their current positions
    const sph::NeighborLists& fluidLists; ///< liquid particle -> `particles`
    AirSolidBlock staticSolids, movingSolids;
    std::vector<const sph::MovingLevelSet*> solids; ///< every solid's shape and motion
    const sph::RunCounters& run;                    ///< time, step, mean neighbour count
    sph::Real mass;                                 ///< particle mass (kg); 0 before it is known
    const sph::ParticleExchange* exchange;          ///< the other processes, or null
};

/// One resampling of the air in a region (see the file comment); run() does it all.
class AirResampler
{
public:
    using Real = sph::Real;
    using Vec3 = sph::Vec3;

    /// @param phase  the region's first phase (< 0: everywhere)
    /// @param count  number of consecutive phases resampled
    AirResampler(AirResamplingInputs inputs, int phase, int count);

    /// Keep, thin, grow and weigh the region's air, in the steps of the file comment.
    void run();

private:
    /// Where a particle lies relative to the region (bit flags, see markZones).
    enum Zone : std::uint8_t { IN_REGION = 1, NEAR_SEEDING = 2, NEAR_BODY = 4 };
    /// The points the new air grows from and the points it keeps r away from (m).
    struct SeedsAndObstacles
    {
        std::vector<Vec3> seeds, obstacles;
    };
    /// What the liquid near the region's air asks of it (AirWeights::Complete), per particle
    /// of the step: the weight f_i it lacks (or -1: not asked) and A_i = sum_air W_ia.
    struct LiquidRequests
    {
        std::vector<Real> wanted, airOf;
    };
    using AskedFlags = std::unique_ptr<std::atomic<std::uint8_t>[]>;

    // The steps of run(), in order.
    void markZones();
    void findBody();
    bool boundBody();
    Real interiorNumberDensity() const;
    void markKeptAir();
    void thinKeptAir();
    SeedsAndObstacles seedsAndObstacles();
    void addSolidObstacles(const sph::BoundaryBlock& block, const sph::Aabb& near,
                           std::vector<Vec3>& obstacles) const;
    std::vector<Vec3> sampleNewAir(const SeedsAndObstacles& points) const;
    void addNewAir(const std::vector<Vec3>& air);
    void matchWeights(const sph::NeighborGrid& freshGrid);
    void completeWeights(const sph::NeighborGrid& freshGrid);

    // The parts of findBody() and completeWeights().
    bool hasLiquidNeighbour(std::size_t i) const;
    bool isFullInterior(std::size_t i) const;
    Real liquidAndSolidSum(std::size_t i, const sph::CubicSplineKernel& kernel,
                           sph::PairBatch& batch) const;
    void addSolidSum(std::size_t i, const sph::CubicSplineKernel& kernel, sph::PairBatch& batch,
                     Real& sum) const;
    AskedFlags markAskingLiquid() const;
    LiquidRequests liquidRequests(const sph::NeighborGrid& freshGrid,
                                  const AskedFlags& asked) const;
    void leastSquaresWeights(const LiquidRequests& requests);

    // The questions the steps ask about a point q (m).
    bool insideSolid(const Vec3& q) const;
    bool insideLiquid(const Vec3& q) const;
    bool nearBodyParticle(const Vec3& q) const;
    sph::Index nearestBodyParticle(const Vec3& q) const;
    /// Whether particle i of the step is this process's own (not a halo copy).
    bool owned(std::size_t i) const { return !mHalo || mHalo[i] == Real(0); }
    /// The halo flags of the particles when shared with other processes, else null.
    const Real* haloFlags() const;

    AirResamplingInputs mIn;
    const Real mR;        ///< kernel radius R (m)
    const Real mr;        ///< Poisson radius r of the air (m)
    const std::size_t mN; ///< particles of the step (the new air comes after them)
    const std::vector<Vec3>& mX;
    const std::vector<sph::ParticleKind>& mKind;
    std::vector<Real>& mTarget; ///< the air's target weights (AIR_TARGET)
    const AirRegion mRegion;
    /// Read through this pointer, fetched again after new air is added: adding particles may
    /// move the channel's storage.
    const Real* mHalo;
    std::vector<std::uint8_t> mZone; ///< per particle of the step: Zone flags
    /// Per particle: whether it is a liquid particle of the body (with a liquid neighbour, or
    /// a halo copy's liquid), and its liquid-and-solid indicator sum_j W_ij (or the largest
    /// Real where it is no seeding candidate).
    std::vector<std::uint8_t> mBody;
    std::vector<Real> mIndicator;
    std::vector<std::uint8_t> mKeep; ///< per particle: region's air that stays
    sph::Aabb mBounds;               ///< of the body (m)
    Real mN0 = 0;                    ///< the interior's number density n0 (1/m^3)
};

} // namespace detail
} // namespace ghost
} // namespace ghostfx
