/// @file   AirResampling.cc
/// @brief  AirResampler: one resampling of the ghost air in a region ([SB12] Sec. 4.3).
#include "AirResampling.h"

#include "GhostInternal.h"

#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/PoissonSampler.h>

#include <algorithm>
#include <limits>
#include <utility>

namespace ghostfx {
namespace ghost {
namespace detail {

using namespace sph;

namespace {

/// A liquid particle seeds new air when its liquid-and-solid indicator is below this fraction
/// of the interior value: at the free surface the indicator is about one half, and it reaches
/// 0.97 about 1.5 h deep (cubic spline, support 3 h), below the 2r = 1.84 h that Bridson's
/// annulus reaches out of the liquid.
constexpr Real SURFACE_SEED_FRACTION = Real(0.97);

/// The indicator of a particle that seeds no air.
constexpr Real NO_SEED = std::numeric_limits<Real>::max();

} // namespace

AirResampler::AirResampler(AirResamplingInputs inputs, int phase, int count)
    : mIn(std::move(inputs))
    , mR(mIn.settings.supportRadius())
    , mr(PoissonSettings::SB12_RADIUS_FACTOR * mIn.settings.spacing)
    , mN(mIn.particles.size())
    , mX(mIn.particles.positions())
    , mKind(mIn.particles.kinds())
    , mTarget(mIn.particles.scalarChannel(AIR_TARGET))
    , mRegion(mR, mIn.settings.airResampleSteps, phase, count)
    , mHalo(haloFlags())
{}

const Real* AirResampler::haloFlags() const
{
    return mIn.exchange ? mIn.particles.scalarChannel(HALO_CHANNEL).data() : nullptr;
}

void AirResampler::run()
{
    markZones();
    findBody();
    if (!boundBody()) return;
    mN0 = interiorNumberDensity();
    markKeptAir();
    thinKeptAir();
    const std::vector<Vec3> air = sampleNewAir(seedsAndObstacles());
    addNewAir(air);
    if (mIn.mass > Real(0)) {
        NeighborGrid freshGrid(mR);
        freshGrid.build(air);
        if (mIn.settings.airWeights == AirWeights::Matched) matchWeights(freshGrid);
        if (mIn.settings.airWeights == AirWeights::Complete) completeWeights(freshGrid);
    }
}

// Per particle: whether it lies in the region resampled now (phase < 0: everywhere), within
// 2r of it (what new air there keeps away from, where its seeds are) or within R (the body
// particles its air and candidates look for).
void AirResampler::markZones()
{
    mZone.assign(mN, 0);
    parallel::forEach(
        0, mN,
        [&](std::size_t i) {
        if (!mRegion.near(mX[i], mR)) return;
        if (mRegion.contains(mX[i])) mZone[i] = IN_REGION | NEAR_SEEDING | NEAR_BODY;
        else if (mRegion.near(mX[i], Real(2) * mr)) mZone[i] = NEAR_SEEDING | NEAR_BODY;
        else mZone[i] = NEAR_BODY;
        },
        2048);
}

// 1. Per liquid particle: its liquid-and-solid indicator sum_j W_ij (ghost solids count:
//    the thin gap between liquid and a wall is not free surface, and air there would hold
//    the liquid off the wall) and whether it has a liquid neighbour. Particles without one
//    move ballistically and get no air ([SB12] Sec. 4.5): like the solids they are
//    obstacles the new air keeps r away from. Air lives within a kernel radius of the body
//    only, so escaped spray neither attracts air nor stretches the sampling region.
//    Halo copies (other processes' particles, with no lists of their own): their liquid
//    counts as body, never as a seed; their air is an obstacle whose fate its owner decides.
void AirResampler::findBody()
{
    mIndicator.assign(mN, NO_SEED);
    mBody.assign(mN, 0);
    if (mHalo) {
        for (std::size_t i = 0; i < mN; ++i) {
            mBody[i] = !owned(i) && mKind[i] == ParticleKind::Liquid;
        }
    }
    forRangeWithBatch(
        mN, mIn.kernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            // Only the liquid within a kernel radius of the region is asked about, and only the
            // seeding candidates need the indicator.
            if (mKind[i] != ParticleKind::Liquid || !(mZone[i] & NEAR_BODY) || !owned(i)) {
                continue;
            }
            mBody[i] = hasLiquidNeighbour(i);
            if (!mBody[i] || !(mZone[i] & NEAR_SEEDING)) continue;
            mIndicator[i] = isFullInterior(i) ? NO_SEED : liquidAndSolidSum(i, kernel, batch);
        }
        },
        512);
}

/// Whether liquid particle i has a liquid neighbour other than itself.
bool AirResampler::hasLiquidNeighbour(std::size_t i) const
{
    for (Index j : mIn.fluidLists[i]) {
        if (j != i && mKind[j] == ParticleKind::Liquid) return true;
    }
    return false;
}

/// Whether liquid particle i is interior, so no seed: no air neighbour and a full
/// neighbourhood (at least 90 % of the mean neighbour count of the last step).
bool AirResampler::isFullInterior(std::size_t i) const
{
    for (Index j : mIn.fluidLists[i]) {
        if (mKind[j] == ParticleKind::GhostAir) return false;
    }
    const std::size_t count = mIn.fluidLists[i].size() + mIn.staticSolids.lists[i].size()
                              + mIn.movingSolids.lists[i].size();
    return mIn.mass > Real(0) && mIn.run.meanNeighbors > 0
           && double(count) >= 0.9 * mIn.run.meanNeighbors;
}

/// Liquid particle i's liquid-and-solid indicator sum_j W_ij, from its lists.
Real AirResampler::liquidAndSolidSum(std::size_t i, const CubicSplineKernel& kernel,
                                     PairBatch& batch) const
{
    Real sum = 0;
    batch.forEachBatch(mX[i], mX.data(), mIn.fluidLists[i], [&](PairBatch& b) {
        for (int k = 0; k < b.n; ++k) b.f[k] = Real(mKind[b.j[k]] == ParticleKind::Liquid);
        for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]);
        sum += b.sum(b.f);
    });
    addSolidSum(i, kernel, batch, sum);
    return sum;
}

/// Adds sum_j W_ij over the ghost solids in liquid particle i's block lists to `sum`.
void AirResampler::addSolidSum(std::size_t i, const CubicSplineKernel& kernel, PairBatch& batch,
                               Real& sum) const
{
    for (const AirSolidBlock* block : {&mIn.staticSolids, &mIn.movingSolids}) {
        batch.forEachBatch(mX[i], block->block.particles().positions().data(), block->lists[i],
                           [&](PairBatch& b) {
            for (int k = 0; k < b.n; ++k) b.f[k] = kernel.W(b.r[k]);
            sum += b.sum(b.f);
        });
    }
}

/// The body's bounding box; false when the region has no body (nothing to resample).
bool AirResampler::boundBody()
{
    std::size_t bodyCount = 0;
    for (std::size_t i = 0; i < mN; ++i) {
        if (!mBody[i]) continue;
        mBounds.expand(mX[i]);
        ++bodyCount;
    }
    return bodyCount > 0;
}

bool AirResampler::nearBodyParticle(const Vec3& q) const
{
    return mIn.grid.anyInRadius(q, mR, [&](Index j) { return mBody[j] != 0; });
}

/// The nearest body particle within R of q, or INVALID_INDEX.
Index AirResampler::nearestBodyParticle(const Vec3& q) const
{
    return mIn.grid.nearest(q, mR, [&](Index j) { return mBody[j] != 0; });
}

bool AirResampler::insideSolid(const Vec3& q) const
{
    for (const MovingLevelSet* solid : mIn.solids) {
        if (solid->phi(q, mIn.run.time) < Real(0)) return true;
    }
    return false;
}

// 2. Inside the liquid: its smoothed indicator sum_j W(x - x_j) / n0, with n0 = rho0 / m the
//    interior value, exceeds one half there (the free surface is its half level). The
//    Poisson test alone is not enough: a relaxed liquid has holes a little wider than r
//    (tests/sph/test_sampler.cc measures 1.05 - 1.1 r), and air seeded into them would sit
//    inside the liquid with p = 0, adding mass where there is no free surface. Before the
//    mass is known (the first layer), n0 is the 75th percentile of the liquid particles'
//    own sums, which lies in the interior.
Real AirResampler::interiorNumberDensity() const
{
    if (mIn.mass > Real(0)) return mIn.settings.restDensity / mIn.mass;
    std::vector<Real> sums;
    for (std::size_t i = 0; i < mN; ++i) {
        if (mBody[i]) sums.push_back(mIndicator[i]);
    }
    std::nth_element(sums.begin(), sums.begin() + sums.size() * 3 / 4, sums.end());
    return sums[sums.size() * 3 / 4];
}

//    The sum only grows (W >= 0, and a float sum of non-negative terms never falls), so
//    once the liquid alone passes the half level the solids are not summed.
bool AirResampler::insideLiquid(const Vec3& q) const
{
    const CubicSplineKernel& kernel = mIn.kernel;
    const Real half = Real(0.5) * mN0;
    Real sum = 0;
    mIn.grid.forEachInRadius(q, mR, [&](Index j, const Vec3&, Real rij) {
        if (mKind[j] == ParticleKind::Liquid) sum += kernel.W(rij);
    });
    for (const AirSolidBlock* b : {&mIn.staticSolids, &mIn.movingSolids}) {
        if (sum > half) return true;
        b->block.grid().forEachInRadius(
            q, mR, [&](Index, const Vec3&, Real rij) { sum += kernel.W(rij); });
    }
    return sum > half;
}

// 3. Keep the air that is still where the layer should be: within a kernel radius of the
//    liquid body, no closer to it than a fraction of r, outside solids and the liquid, and
//    not crowded (thinKeptAir). The rest fades out, and new air fades in, over the steps
//    until the next resampling: replacing the whole layer at once (as [SB12] Sec. 4.3
//    describes) makes the surface density jump by a few percent at every resampling, which
//    with the paper's soft stiffness pumps energy into the liquid; fading is the remedy
//    [SB12] Sec. 4.7 suggests.
void AirResampler::markKeptAir()
{
    const Real keepDistance = mIn.settings.airKeepFraction * mr;
    mKeep.assign(mN, 0);
    parallel::forEach(0, mN, [&](std::size_t i) {
        if (mKind[i] != ParticleKind::GhostAir || mTarget[i] == Real(0) || !(mZone[i] & IN_REGION)
            || !owned(i))
            return;
        // The nearest body particle within R, from the step's list (the liquid within R).
        Real nearest2 = std::numeric_limits<Real>::max();
        for (Index j : mIn.fluidLists[i]) {
            if (mBody[j]) nearest2 = std::min(nearest2, (mX[i] - mX[j]).lengthSqr());
        }
        mKeep[i] = nearest2 != std::numeric_limits<Real>::max()
                   && std::sqrt(nearest2) >= keepDistance && !insideSolid(mX[i])
                   && !insideLiquid(mX[i]);
    });
}

//    Air advected with converging liquid bunches up: of two air particles closer than r, the
//    later one goes. The thinning distance is r, the distance new air keeps from everything:
//    thinning at the keep fraction of r would let every resampling pack the layer a little
//    closer (measured: +35 % air mass over ten resamplings in a zero-gravity cube).
//    The living air of the other regions near this one comes first in the order: kept air
//    too close to it goes, so no air piles up along the borders of the regions.
void AirResampler::thinKeptAir()
{
    const Real thinDistance = mr;
    std::vector<Vec3> airX;
    std::vector<std::size_t> airIndex;
    for (std::size_t i = 0; i < mN; ++i) {
        if (mKind[i] == ParticleKind::GhostAir && mTarget[i] != Real(0)
            && mZone[i] == (NEAR_SEEDING | NEAR_BODY)) {
            airX.push_back(mX[i]);
            airIndex.push_back(i);
        }
    }
    const std::size_t others = airX.size();
    for (std::size_t i = 0; i < mN; ++i) {
        if (mKeep[i]) {
            airX.push_back(mX[i]);
            airIndex.push_back(i);
        }
    }
    NeighborGrid airGrid(thinDistance);
    airGrid.build(airX);
    for (std::size_t a = others; a < airX.size(); ++a) {
        airGrid.forEachNeighbor(Index(a), [&](Index b, const Vec3&, Real) {
            if (b < a && (b < others || mKeep[airIndex[b]])) mKeep[airIndex[a]] = 0;
        });
    }
}

// 4. Seeds: the body's particles near the free surface and the kept air; obstacles: the
//    rest of the liquid and the solid particles near the layer. Fading air is no obstacle:
//    the new layer cross-fades with it. Outside the region the air lives on and is an
//    obstacle too. The region's air that is not kept fades out.
AirResampler::SeedsAndObstacles AirResampler::seedsAndObstacles()
{
    SeedsAndObstacles points;
    std::vector<Vec3>& seeds = points.seeds;
    std::vector<Vec3>& obstacles = points.obstacles;
    const Aabb near = mBounds.padded(mR + Real(2) * mr);
    for (std::size_t i = 0; i < mN; ++i) {
        if (!(mZone[i] & NEAR_SEEDING)) continue;
        if (mKind[i] == ParticleKind::GhostAir) {
            if (!(mZone[i] & IN_REGION) || !owned(i)) {
                if (mTarget[i] != Real(0)) obstacles.push_back(mX[i]);
            } else if (mKeep[i]) {
                seeds.push_back(mX[i]);
            } else {
                mTarget[i] = Real(0);
            }
        } else if (mBody[i] && mIndicator[i] < SURFACE_SEED_FRACTION * mN0) {
            seeds.push_back(mX[i]);
        } else {
            obstacles.push_back(mX[i]);
        }
    }
    for (const AirSolidBlock* b : {&mIn.staticSolids, &mIn.movingSolids}) {
        addSolidObstacles(b->block, near, obstacles);
    }
    return points;
}

/// Appends the block's solid particles within 2r of the region and in `near` (the body's box
/// grown by R + 2r) to `obstacles`. The solid grid's cells are tested whole first: a cell none
/// of whose points lies within 2r of the region holds no obstacle (most of a tank's cells),
/// and its particles are never read.
void AirResampler::addSolidObstacles(const BoundaryBlock& block, const Aabb& near,
                                     std::vector<Vec3>& obstacles) const
{
    if (block.empty()) return;
    auto add = [&](const Vec3& q) {
        if (mRegion.near(q, Real(2) * mr)) obstacles.push_back(q);
    };
    if (block.stale()) {
        // Not yet sorted (added since the last step): every particle.
        for (const Vec3& q : block.particles().positions()) {
            if (near.contains(q)) add(q);
        }
        return;
    }
    const NeighborGrid& grid = block.grid();
    const Real side = grid.cellSize();
    // The box centre +- (side / 2 + 2r) holds the cell's box grown by 2r (AirRegion::near
    // tests boxes); the slack covers a point that rounding put in the next cell.
    const Real reach = Real(0.5) * side + Real(2) * mr + Real(1e-3) * side;
    grid.forEachInBox(
        near,
        [&](const NeighborGrid::Cell& c) {
        const Vec3 centre((Real(c.i) + Real(0.5)) * side, (Real(c.j) + Real(0.5)) * side,
                          (Real(c.k) + Real(0.5)) * side);
        const Real margin =
            reach
            + Real(1e-5)
                  * std::max({std::abs(centre[0]), std::abs(centre[1]), std::abs(centre[2])});
        return margin > mRegion.largestMargin() || mRegion.near(centre, margin);
        },
        [&](Index, const Vec3& q) { add(q); });
}

/// The new air: Bridson's sampler grown from the seeds, candidates in the region, owned by
/// this process, within R of the body and outside the solids and the liquid.
std::vector<Vec3> AirResampler::sampleNewAir(const SeedsAndObstacles& points) const
{
    auto inPhase = [&](const Vec3& q) { return mRegion.contains(q); };
    auto accept = [&](const Vec3& q) {
        return inPhase(q) && (!mIn.exchange || mIn.exchange->owns(q)) && nearBodyParticle(q)
               && !insideSolid(q) && !insideLiquid(q);
    };
    PoissonSettings ps = PoissonSettings::forSpacing(mIn.settings.spacing);
    ps.volumeAttempts = PoissonSettings::SB12_SEEDED_ATTEMPTS;
    ps.seed = mIn.settings.seed ^ (0x9e3779b97f4a7c15ULL * (mIn.run.step + 1));
    return PoissonDiskSampler(ps).sampleFromSeeds(points.seeds, points.obstacles, accept,
                                                  mBounds.padded(mR), inPhase);
}

// 5. The new air: faded in from weight 0 (the very first layer is there from the start),
//    with the velocity of the nearest body particle ([SB12] Sec. 4.3).
void AirResampler::addNewAir(const std::vector<Vec3>& air)
{
    ParticleSet& particles = mIn.particles;
    const Index first = particles.addBatch(air, mIn.mass, ParticleKind::GhostAir);
    mHalo = haloFlags();
    const bool fade = mIn.run.initialized;
    auto& weight = particles.scalarChannel(AIR_WEIGHT);
    Real* progress =
        particles.hasScalarChannel(AIR_FADE) ? particles.scalarChannel(AIR_FADE).data() : nullptr;
    auto& v = particles.velocities();
    parallel::forEach(first, particles.size(), [&](std::size_t i) {
        weight[i] = fade ? Real(0) : Real(1);
        if (progress) progress[i] = weight[i];
        particles.masses()[i] = weight[i] * mIn.mass;
        const Index j = nearestBodyParticle(particles.positions()[i]);
        v[i] = j == INVALID_INDEX ? Vec3(0) : v[j];
        particles.densities()[i] = mIn.settings.restDensity;
    });
}

// 6. Density-matched weights (AirWeights::Matched). Each resampling adds air in the gaps the
//    kept air leaves, so over many resamplings the layer packs ever closer (towards a maximal
//    Poisson packing, denser than one pass of Bridson's sampler with 8 attempts): with weight
//    1 the air would weigh more and more, raise the density of the surface particles and push
//    the liquid apart (a zero-gravity cube spreads within 2 s, [SB12] Fig. 4 says it must
//    not). So the region's air aims at the weight that makes its own number density, counted
//    with the liquid and the other air, that of the liquid interior: min(1, n0 / sigma_a),
//    sigma_a = sum_j W(x_a - x_j). Air in a layer as dense as the liquid keeps weight 1.
//    `freshGrid` holds the new air.
void AirResampler::matchWeights(const NeighborGrid& freshGrid)
{
    const CubicSplineKernel& kernel = mIn.kernel;
    parallel::forEach(
        0, mX.size(),
        [&](std::size_t i) {
        if (mKind[i] != ParticleKind::GhostAir || mTarget[i] == Real(0)) return;
        if (i < mN && (!(mZone[i] & IN_REGION) || !owned(i))) return;
        // The liquid and the living air of the step's grid, and the new air.
        Real sigma = 0;
        mIn.grid.forEachInRadius(mX[i], mR, [&](Index j, const Vec3&, Real rij) {
            if (mKind[j] == ParticleKind::Liquid || mTarget[j] != Real(0)) sigma += kernel.W(rij);
        });
        freshGrid.forEachInRadius(mX[i], mR,
                                  [&](Index, const Vec3&, Real rij) { sigma += kernel.W(rij); });
        mTarget[i] = sigma > mN0 ? mN0 / sigma : Real(1);
        },
        64);
}

//    AirWeights::Complete: the weight is what the liquid next to the air lacks. The matched
//    weights look at the air's own packing, yet a surface particle's density is half liquid
//    and half air, and the layer still packs a little closer at every resampling (a
//    zero-gravity cube grows 4-6 % in gyration within 2 s). Here each liquid particle near
//    the region asks for the weight f_i that brings its density sum to rho0,
//      f_i = (n0 - sum_liquid,solid W_ij) / A_i,   A_i = sum_air W_ia  (weight 1 for all),
//    within [0, 1] (air never weighs more than liquid; liquid at rest density without air
//    asks for none), and each air particle of the region takes the least-squares weight
//    for its liquid neighbours, sum_i W_ai A_i^2 f_i / sum_i W_ai A_i^2: the particles with
//    much air decide, those whose neighbourhood is nearly complete (f_i a noisy ratio of
//    small numbers) hardly count. Measured (bench/history/diary-2026-11.md, "Air that
//    completes the liquid's density"): the zero-gravity cube -0.4 % in gyration over 2 s.
void AirResampler::completeWeights(const NeighborGrid& freshGrid)
{
    const AskedFlags asked = markAskingLiquid();
    leastSquaresWeights(liquidRequests(freshGrid, asked));
}

/// The liquid within R of the region's air, the only liquid whose request is read: marked
/// from the air's side (the region's air is a small share of the particles near it), from
/// the step's lists for the kept air and by a search for the new air. Many air particles
/// mark the same liquid particle: the flags are atomic (relaxed, as only the value 1 is
/// written and the pass that reads them starts after this one has joined).
AirResampler::AskedFlags AirResampler::markAskingLiquid() const
{
    AskedFlags asked(new std::atomic<std::uint8_t>[mN]());
    auto ask = [&](Index j) {
        if (mKind[j] == ParticleKind::Liquid) asked[j].store(1, std::memory_order_relaxed);
    };
    parallel::forEach(
        0, mX.size(),
        [&](std::size_t a) {
        if (mKind[a] != ParticleKind::GhostAir || mTarget[a] == Real(0)) return;
        if (a >= mN) {
            mIn.grid.forEachInRadius(mX[a], mR, [&](Index j, const Vec3&, Real) { ask(j); });
        } else if ((mZone[a] & IN_REGION) && owned(a)) {
            for (Index j : mIn.fluidLists[a]) ask(j);
        }
        },
        64);
    return asked;
}

/// Each asking liquid particle's f_i and A_i. Its sums come from the step's lists (this
/// resampling runs on the positions they were built for): the living air and the liquid
/// within R are in its fluid list, the solids in its block lists; only the new air
/// (`freshGrid`) needs a search.
AirResampler::LiquidRequests AirResampler::liquidRequests(const NeighborGrid& freshGrid,
                                                          const AskedFlags& asked) const
{
    LiquidRequests requests{std::vector<Real>(mN, Real(-1)), std::vector<Real>(mN, Real(0))};
    forRangeWithBatch(
        mN, mIn.kernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            // A halo copy's own neighbourhood reaches past this process's copies: not asked.
            if (!asked[i].load(std::memory_order_relaxed) || !(mZone[i] & NEAR_BODY) || !mBody[i]
                || !owned(i))
                continue;
            Real airUnit = 0;
            freshGrid.forEachInRadius(
                mX[i], mR, [&](Index, const Vec3&, Real rij) { airUnit += kernel.W(rij); });
            Real dense = 0;
            batch.forEachBatch(mX[i], mX.data(), mIn.fluidLists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) {
                    const Index j = b.j[k];
                    b.f[k] = Real(mKind[j] == ParticleKind::Liquid);
                    b.g[k] = Real(mKind[j] == ParticleKind::GhostAir && mTarget[j] != Real(0));
                }
                for (int k = 0; k < b.n; ++k) {
                    const Real w = kernel.W(b.r[k]);
                    b.f[k] *= w;
                    b.g[k] *= w;
                }
                dense += b.sum(b.f);
                airUnit += b.sum(b.g);
            });
            addSolidSum(i, kernel, batch, dense);
            if (airUnit > Real(0)) {
                requests.wanted[i] = std::clamp((mN0 - dense) / airUnit, Real(0), Real(1));
                requests.airOf[i] = airUnit;
            }
        }
        },
        64);
    return requests;
}

/// Each air particle of the region: the least-squares weight of its asking liquid
/// neighbours. The kept air reads its list (the liquid within R), the new air searches.
void AirResampler::leastSquaresWeights(const LiquidRequests& requests)
{
    const std::vector<Real>& wanted = requests.wanted;
    const std::vector<Real>& airOf = requests.airOf;
    forRangeWithBatch(
        mX.size(), mIn.kernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (mKind[i] != ParticleKind::GhostAir || mTarget[i] == Real(0)) continue;
            Real weight = 0, sum = 0;
            if (i < mN) {
                if (!(mZone[i] & IN_REGION) || !owned(i)) continue;
                batch.forEachBatch(mX[i], mX.data(), mIn.fluidLists[i], [&](PairBatch& b) {
                    for (int k = 0; k < b.n; ++k) {
                        const Index j = b.j[k];
                        const bool asks = wanted[j] >= Real(0);
                        b.f[k] = asks ? sqr(airOf[j]) : Real(0);
                        b.g[k] = asks ? wanted[j] : Real(0);
                    }
                    for (int k = 0; k < b.n; ++k) {
                        b.f[k] *= kernel.W(b.r[k]);
                        b.g[k] *= b.f[k];
                    }
                    weight += b.sum(b.f);
                    sum += b.sum(b.g);
                });
            } else {
                mIn.grid.forEachInRadius(mX[i], mR, [&](Index j, const Vec3&, Real rij) {
                    if (wanted[j] < Real(0)) return;
                    const Real w = kernel.W(rij) * sqr(airOf[j]);
                    weight += w;
                    sum += w * wanted[j];
                });
            }
            mTarget[i] = weight > Real(0) ? sum / weight : Real(1);
        }
        },
        64);
}

} // namespace detail
} // namespace ghost
} // namespace ghostfx
