/// @file   GhostAir.cc
/// @brief  The ghost air layer of [SB12] Sec. 4.3: sampled around the liquid body, kept where it
///         still belongs, faded in and out between resamplings.
/// @details Resampling runs right after the step's neighbour search and reuses it: the grid of
///          liquid and air answers the nearest-body and inside-the-liquid questions, and the
///          liquid particles' lists give each one's liquid-and-solid indicator. New air grows
///          only from the particles near the free surface (and the kept air): growth from a
///          particle deeper than 2r lands inside the liquid and is refused anyway, so seeding
///          from the whole body (as before) spent most of the resampling on rejected candidates.
///          New air starts at weight 0 and is appended after the lists were built; it takes part
///          in the sums from the next step on.
///
///          The layer is resampled region by region: space is cut into blocks four kernel radii
///          wide, each block belongs to one of `airResampleSteps` phases (AirRegion), and step
///          s resamples the blocks of phase s mod airResampleSteps. Every
///          part of the layer is still resampled every airResampleSteps steps ([SB12] Sec. 4.3),
///          but each step does a tenth of the work, so no step is much slower than the others.
///          DFSPH's steps are several of [SB12]'s long, so a DFSPH step resamples as many
///          consecutive phases as [SB12]'s steps it spans (GhostSettings::airResampleSpan).
#include "ghostfx/ghost/GhostSolver.h"

#include "GhostInternal.h"

#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/PoissonSampler.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

namespace {

/// A liquid particle seeds new air when its liquid-and-solid indicator is below this fraction
/// of the interior value: at the free surface the indicator is about one half, and it reaches
/// 0.97 about 1.5 h deep (cubic spline, support 3 h), below the 2r = 1.84 h that Bridson's
/// annulus reaches out of the liquid.
constexpr Real SURFACE_SEED_FRACTION = Real(0.97);

} // namespace

/// The region of `count` consecutive resampling phases from `phase` on: blocks of side 4R
/// whose coordinates (i, j, k) give (i + 3 j + 5 k) mod N in phase, ..., phase + count - 1
/// (mod N). With N = 10 no two blocks that touch (even at a corner) share a phase, and the
/// phases take turns evenly through space.
class AirRegion
{
public:
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
    /// The largest margin near() takes: half a block.
    Real largestMargin() const { return Real(0.5) * mBlock; }

    int phaseOf(const Vec3& x) const
    {
        const std::int64_t c = block(x[0]) + 3 * block(x[1]) + 5 * block(x[2]);
        return int(((c % mPhases) + mPhases) % mPhases);
    }
    bool contains(const Vec3& x) const { return mPhase < 0 || mInRegion[phaseOf(x) + MAX_OFFSET]; }
    /// Whether x lies within `margin` (at most half a block) of the region: the blocks the box
    /// x +- margin touches are the own block and, per axis, the neighbour on the side where x
    /// is closer than the margin to the face.
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
    Real mBlock, mInvBlock;
    int mPhases, mPhase;
    std::vector<std::uint8_t> mInRegion; ///< see the constructor
};

/// Where a particle lies relative to the region resampled now (bit flags).
enum Zone : std::uint8_t { IN_REGION = 1, NEAR_SEEDING = 2, NEAR_BODY = 4 };

void GhostSolver::resampleAir(int phase, int count)
{
    // Needs the grid and lists of searchNeighbors() for the current positions.
    const auto start = std::chrono::steady_clock::now();
    const Real R = mSettings.supportRadius();
    const Real r = PoissonSettings::SB12_RADIUS_FACTOR * mSettings.spacing;
    const double time = mRun.time;
    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& kind = mParticles.kinds();
    // The region resampled now (phase < 0: everywhere) and, per particle, whether it lies in
    // it, within 2r of it (what new air there keeps away from, where its seeds are) or within
    // R (the body particles its air and candidates look for).
    const AirRegion region(R, mSettings.airResampleSteps, phase, count);
    std::vector<std::uint8_t> zone(n, 0);
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        if (!region.near(x[i], R)) return;
        if (region.contains(x[i])) zone[i] = IN_REGION | NEAR_SEEDING | NEAR_BODY;
        else if (region.near(x[i], Real(2) * r)) zone[i] = NEAR_SEEDING | NEAR_BODY;
        else zone[i] = NEAR_BODY;
        },
        2048);
    auto inPhase = [&](const Vec3& q) { return region.contains(q); };

    // 1. Per liquid particle: its liquid-and-solid indicator sum_j W_ij (ghost solids count:
    //    the thin gap between liquid and a wall is not free surface, and air there would hold
    //    the liquid off the wall) and whether it has a liquid neighbour. Particles without one
    //    move ballistically and get no air ([SB12] Sec. 4.5): like the solids they are
    //    obstacles the new air keeps r away from. Air lives within a kernel radius of the body
    //    only, so escaped spray neither attracts air nor stretches the sampling region.
    std::vector<Real> indicator(n, std::numeric_limits<Real>::max());
    std::vector<std::uint8_t> body(n, 0);
    // Halo copies (other processes' particles, with no lists of their own): their liquid counts
    // as body, never as a seed; their air is an obstacle whose fate its owner decides.
    // (Read through `halo`, which is fetched again after new air is added below: adding
    // particles may move the channel's storage.)
    const Real* halo = haloFlags();
    auto owned = [&halo](std::size_t i) { return !halo || halo[i] == Real(0); };
    if (halo) {
        for (std::size_t i = 0; i < n; ++i) body[i] = !owned(i) && kind[i] == ParticleKind::Liquid;
    }
    // Adds sum_j W_ij over the ghost solids in liquid particle i's block lists to `sum`.
    auto addSolidSum =
        [&](std::size_t i, const CubicSplineKernel& kernel, PairBatch& batch, Real& sum) {
        for (const SolidBlock* block : {&mStatic, &mMoving}) {
            batch.forEachBatch(x[i], block->block.particles().positions().data(), block->lists[i],
                               [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = kernel.W(b.r[k]);
                sum += b.sum(b.f);
            });
        }
    };
    forRangeWithBatch(
        n, mKernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            // Only the liquid within a kernel radius of the region is asked about, and only the
            // seeding candidates need the indicator.
            if (kind[i] != ParticleKind::Liquid || !(zone[i] & NEAR_BODY) || !owned(i)) continue;
            for (Index j : mFluidLists[i]) {
                if (j != i && kind[j] == ParticleKind::Liquid) {
                    body[i] = 1;
                    break;
                }
            }
            if (!body[i] || !(zone[i] & NEAR_SEEDING)) continue;
            // A particle with no air neighbour and a full neighbourhood is interior: no seed.
            // (Full: at least 90 % of the mean neighbour count of the last step.)
            bool air = false;
            for (Index j : mFluidLists[i]) {
                if (kind[j] == ParticleKind::GhostAir) {
                    air = true;
                    break;
                }
            }
            const std::size_t count =
                mFluidLists[i].size() + mStatic.lists[i].size() + mMoving.lists[i].size();
            if (!air && mMass > Real(0) && mRun.meanNeighbors > 0
                && double(count) >= 0.9 * mRun.meanNeighbors) {
                indicator[i] = std::numeric_limits<Real>::max();
                continue;
            }
            Real sum = 0;
            batch.forEachBatch(x[i], x.data(), mFluidLists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = Real(kind[b.j[k]] == ParticleKind::Liquid);
                for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]);
                sum += b.sum(b.f);
            });
            addSolidSum(i, kernel, batch, sum);
            indicator[i] = sum;
        }
        },
        512);
    Aabb bounds;
    std::size_t bodyCount = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!body[i]) continue;
        bounds.expand(x[i]);
        ++bodyCount;
    }
    if (bodyCount == 0) {
        mTimings.airResampling += secondsSince(start);
        return;
    }
    auto nearBody = [&](const Vec3& q, Real* distance = nullptr) {
        return mGrid.nearest(
            q, R, [&](Index j) { return body[j] != 0; }, distance);
    };
    auto insideSolid = [&](const Vec3& q) {
        for (const auto& solid : mSolids) {
            if (solid->phi(q, time) < Real(0)) return true;
        }
        return false;
    };

    // 2. Inside the liquid: its smoothed indicator sum_j W(x - x_j) / n0, with n0 = rho0 / m the
    //    interior value, exceeds one half there (the free surface is its half level). The
    //    Poisson test alone is not enough: a relaxed liquid has holes a little wider than r
    //    (tests/sph/test_sampler.cc measures 1.05 - 1.1 r), and air seeded into them would sit
    //    inside the liquid with p = 0, adding mass where there is no free surface. Before the
    //    mass is known (the first layer), n0 is the 75th percentile of the liquid particles'
    //    own sums, which lies in the interior.
    Real n0 = 0;
    if (mMass > Real(0)) {
        n0 = mSettings.restDensity / mMass;
    } else {
        std::vector<Real> sums;
        for (std::size_t i = 0; i < n; ++i) {
            if (body[i]) sums.push_back(indicator[i]);
        }
        std::nth_element(sums.begin(), sums.begin() + sums.size() * 3 / 4, sums.end());
        n0 = sums[sums.size() * 3 / 4];
    }
    //    The sum only grows (W >= 0, and a float sum of non-negative terms never falls), so
    //    once the liquid alone passes the half level the solids are not summed.
    auto insideLiquid = [&](const Vec3& q) {
        const Real half = Real(0.5) * n0;
        Real sum = 0;
        mGrid.forEachInRadius(q, R, [&](Index j, const Vec3&, Real rij) {
            if (kind[j] == ParticleKind::Liquid) sum += mKernel.W(rij);
        });
        for (const SolidBlock* b : {&mStatic, &mMoving}) {
            if (sum > half) return true;
            b->block.grid().forEachInRadius(
                q, R, [&](Index, const Vec3&, Real rij) { sum += mKernel.W(rij); });
        }
        return sum > half;
    };

    // 3. Keep the air that is still where the layer should be: within a kernel radius of the
    //    liquid body, no closer to it than a fraction of r, outside solids and the liquid, and
    //    not crowded (air advected with converging liquid bunches up: of two air particles
    //    closer than r, the later one goes). The rest fades out, and new air
    //    fades in, over the steps until the next resampling: replacing the whole layer at once
    //    (as [SB12] Sec. 4.3 describes) makes the surface density jump by a few percent at
    //    every resampling, which with the paper's soft stiffness pumps energy into the liquid;
    //    fading is the remedy [SB12] Sec. 4.7 suggests.
    const Real keepDistance = mSettings.airKeepFraction * r;
    auto& target = mParticles.scalarChannel(AIR_TARGET);
    std::vector<std::uint8_t> keep(n, 0);
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] != ParticleKind::GhostAir || target[i] == Real(0) || !(zone[i] & IN_REGION)
            || !owned(i))
            return;
        // The nearest body particle within R, from the step's list (the liquid within R).
        Real nearest2 = std::numeric_limits<Real>::max();
        for (Index j : mFluidLists[i]) {
            if (body[j]) nearest2 = std::min(nearest2, (x[i] - x[j]).lengthSqr());
        }
        keep[i] = nearest2 != std::numeric_limits<Real>::max()
                  && std::sqrt(nearest2) >= keepDistance && !insideSolid(x[i])
                  && !insideLiquid(x[i]);
    });
    //    The thinning distance is r, the distance new air keeps from everything: thinning at
    //    the keep fraction of r (as before) let every resampling pack the layer a little
    //    closer (+35 % air mass over ten resamplings in a zero-gravity cube).
    const Real thinDistance = r;
    {
        // The living air of the other regions near this one comes first in the order: kept air
        // too close to it goes, so no air piles up along the borders of the regions.
        std::vector<Vec3> airX;
        std::vector<std::size_t> airIndex;
        std::size_t others = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (kind[i] == ParticleKind::GhostAir && target[i] != Real(0)
                && zone[i] == (NEAR_SEEDING | NEAR_BODY)) {
                airX.push_back(x[i]);
                airIndex.push_back(i);
            }
        }
        others = airX.size();
        for (std::size_t i = 0; i < n; ++i) {
            if (keep[i]) {
                airX.push_back(x[i]);
                airIndex.push_back(i);
            }
        }
        NeighborGrid airGrid(thinDistance);
        airGrid.build(airX);
        for (std::size_t a = others; a < airX.size(); ++a) {
            airGrid.forEachNeighbor(Index(a), [&](Index b, const Vec3&, Real) {
                if (b < a && (b < others || keep[airIndex[b]])) keep[airIndex[a]] = 0;
            });
        }
    }

    // 4. Seeds: the body's particles near the free surface and the kept air; obstacles: the
    //    rest of the liquid and the solid particles near the layer. Fading air is no obstacle:
    //    the new layer cross-fades with it.
    //    Outside the region the air lives on and is an obstacle too.
    std::vector<Vec3> seeds, obstacles;
    const Aabb near = bounds.padded(R + Real(2) * r);
    for (std::size_t i = 0; i < n; ++i) {
        if (!(zone[i] & NEAR_SEEDING)) continue;
        if (kind[i] == ParticleKind::GhostAir) {
            if (!(zone[i] & IN_REGION) || !owned(i)) {
                if (target[i] != Real(0)) obstacles.push_back(x[i]);
            } else if (keep[i]) {
                seeds.push_back(x[i]);
            } else {
                target[i] = Real(0);
            }
        } else if (body[i] && indicator[i] < SURFACE_SEED_FRACTION * n0) {
            seeds.push_back(x[i]);
        } else {
            obstacles.push_back(x[i]);
        }
    }
    //    The solids: those within 2r of the region, in the body's box. The solid grid's cells
    //    are tested whole first: a cell none of whose points lies within 2r of the region holds
    //    no obstacle (most of a tank's cells), and its particles are never read.
    for (const SolidBlock* b : {&mStatic, &mMoving}) {
        if (b->block.empty()) continue;
        auto add = [&](const Vec3& q) {
            if (region.near(q, Real(2) * r)) obstacles.push_back(q);
        };
        if (b->block.stale()) {
            // Not yet sorted (added since the last step): every particle.
            for (const Vec3& q : b->block.particles().positions()) {
                if (near.contains(q)) add(q);
            }
            continue;
        }
        const NeighborGrid& grid = b->block.grid();
        const Real side = grid.cellSize();
        // The box centre +- (side / 2 + 2r) holds the cell's box grown by 2r (AirRegion::near
        // tests boxes); the slack covers a point that rounding put in the next cell.
        const Real reach = Real(0.5) * side + Real(2) * r + Real(1e-3) * side;
        grid.forEachInBox(
            near,
            [&](const NeighborGrid::Cell& c) {
            const Vec3 centre((Real(c.i) + Real(0.5)) * side, (Real(c.j) + Real(0.5)) * side,
                              (Real(c.k) + Real(0.5)) * side);
            const Real margin =
                reach
                + Real(1e-5)
                      * std::max({std::abs(centre[0]), std::abs(centre[1]), std::abs(centre[2])});
            return margin > region.largestMargin() || region.near(centre, margin);
            },
            [&](Index, const Vec3& q) { add(q); });
    }

    auto accept = [&](const Vec3& q) {
        return inPhase(q) && (!mExchange || mExchange->owns(q))
               && mGrid.anyInRadius(q, R, [&](Index j) { return body[j] != 0; }) && !insideSolid(q)
               && !insideLiquid(q);
    };
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.volumeAttempts = PoissonSettings::SB12_SEEDED_ATTEMPTS;
    ps.seed = mSettings.seed ^ (0x9e3779b97f4a7c15ULL * (mRun.step + 1));
    const std::vector<Vec3> air =
        PoissonDiskSampler(ps).sampleFromSeeds(seeds, obstacles, accept, bounds.padded(R), inPhase);

    // 5. The new air: faded in from weight 0 (the very first layer is there from the start),
    //    with the velocity of the nearest body particle ([SB12] Sec. 4.3).
    const Index first = mParticles.addBatch(air, mMass, ParticleKind::GhostAir);
    halo = haloFlags();
    const bool fade = mRun.initialized;
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    auto& v = mParticles.velocities();
    parallel::forEach(first, mParticles.size(), [&](std::size_t i) {
        weight[i] = fade ? Real(0) : Real(1);
        mParticles.masses()[i] = weight[i] * mMass;
        const Index j = nearBody(mParticles.positions()[i]);
        v[i] = j == INVALID_INDEX ? Vec3(0) : v[j];
        mParticles.densities()[i] = mSettings.restDensity;
    });

    // 6. Density-matched weights. Each resampling adds air in the gaps the kept air leaves, so
    //    over many resamplings the layer packs ever closer (towards a maximal Poisson packing,
    //    denser than one pass of Bridson's sampler with 8 attempts): with weight 1 the air
    //    would weigh more and more, raise the density of the surface particles and push the
    //    liquid apart (a zero-gravity cube spreads within 2 s, [SB12] Fig. 4 says it must not).
    //    So the region's air aims at the weight that makes its own number density, counted
    //    with the liquid and the other air, that of the liquid interior: min(1, n0 / sigma_a),
    //    sigma_a = sum_j W(x_a - x_j). Air in a layer as dense as the liquid keeps weight 1.
    if (mMass > Real(0) && mSettings.airWeights == AirWeights::Matched) {
        const auto& xs = mParticles.positions();
        NeighborGrid freshGrid(R);
        freshGrid.build(air);
        parallel::forEach(
            0, xs.size(),
            [&](std::size_t i) {
            if (mParticles.kinds()[i] != ParticleKind::GhostAir || target[i] == Real(0)) return;
            if (i < n && (!(zone[i] & IN_REGION) || !owned(i))) return;
            // The liquid and the living air of the step's grid, and the new air.
            Real sigma = 0;
            mGrid.forEachInRadius(xs[i], R, [&](Index j, const Vec3&, Real rij) {
                if (kind[j] == ParticleKind::Liquid || target[j] != Real(0))
                    sigma += mKernel.W(rij);
            });
            freshGrid.forEachInRadius(
                xs[i], R, [&](Index, const Vec3&, Real rij) { sigma += mKernel.W(rij); });
            target[i] = sigma > n0 ? n0 / sigma : Real(1);
            },
            64);
    }
    //    AirWeights::Complete: the weight is what the liquid next to the air lacks. The matched
    //    weights above look at the air's own packing, yet a surface particle's density is
    //    half liquid and half air, and the layer still packs a little closer at every
    //    resampling (a zero-gravity cube grows 4-6 % in gyration within 2 s). Here each liquid
    //    particle near the region asks for the weight f_i that brings its density sum to rho0,
    //      f_i = (n0 - sum_liquid,solid W_ij) / A_i,   A_i = sum_air W_ia  (weight 1 for all),
    //    within [0, 1] (air never weighs more than liquid; liquid at rest density without air
    //    asks for none), and each air particle of the region takes the least-squares weight
    //    for its liquid neighbours, sum_i W_ai A_i^2 f_i / sum_i W_ai A_i^2: the particles with
    //    much air decide, those whose neighbourhood is nearly complete (f_i a noisy ratio of
    //    small numbers) hardly count. Measured (bench/history/diary-2026-11.md, "Air that completes
    //    the liquid's density"): the zero-gravity cube -0.4 % in gyration over 2 s.
    if (mMass > Real(0) && mSettings.airWeights == AirWeights::Complete) {
        const auto& xs = mParticles.positions();
        NeighborGrid freshGrid(R);
        freshGrid.build(air);
        std::vector<Real> wanted(n, Real(-1)); // f_i, or -1: not asked
        std::vector<Real> airOf(n, Real(0));   // sum_air W_ia at weight 1
        // Only the liquid within R of this region's air is read below, so only it asks: marked
        // from the air's side (the region's air is a small share of the particles near it),
        // from the step's lists for the kept air and by a search for the air added above.
        // Many air particles mark the same liquid particle: the flags are atomic (relaxed, as
        // only the value 1 is written and the pass below starts after this one has joined).
        std::unique_ptr<std::atomic<std::uint8_t>[]> asked(new std::atomic<std::uint8_t>[n]());
        auto ask = [&](Index j) {
            if (kind[j] == ParticleKind::Liquid) asked[j].store(1, std::memory_order_relaxed);
        };
        parallel::forEach(
            0, xs.size(),
            [&](std::size_t a) {
            if (kind[a] != ParticleKind::GhostAir || target[a] == Real(0)) return;
            if (a >= n) {
                mGrid.forEachInRadius(xs[a], R, [&](Index j, const Vec3&, Real) { ask(j); });
            } else if ((zone[a] & IN_REGION) && owned(a)) {
                for (Index j : mFluidLists[a]) ask(j);
            }
            },
            64);
        // The asking liquid's sums come from the step's lists (this resampling runs on the
        // positions they were built for): the living air and the liquid within R are in its
        // fluid list, the solids in its block lists; only the new air needs a search.
        forRangeWithBatch(
            n, mKernel,
            [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
            for (std::size_t i = lo; i < hi; ++i) {
                // A halo copy's own neighbourhood reaches past this process's copies: not
                // asked.
                if (!asked[i].load(std::memory_order_relaxed) || !(zone[i] & NEAR_BODY) || !body[i]
                    || !owned(i))
                    continue;
                Real airUnit = 0;
                freshGrid.forEachInRadius(
                    xs[i], R, [&](Index, const Vec3&, Real rij) { airUnit += kernel.W(rij); });
                Real dense = 0;
                batch.forEachBatch(xs[i], xs.data(), mFluidLists[i], [&](PairBatch& b) {
                    for (int k = 0; k < b.n; ++k) {
                        const Index j = b.j[k];
                        b.f[k] = Real(kind[j] == ParticleKind::Liquid);
                        b.g[k] = Real(kind[j] == ParticleKind::GhostAir && target[j] != Real(0));
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
                    wanted[i] = std::clamp((n0 - dense) / airUnit, Real(0), Real(1));
                    airOf[i] = airUnit;
                }
            }
            },
            64);
        // Each air particle of the region: the kept air reads its list (the liquid within R),
        // the new air searches.
        forRangeWithBatch(
            xs.size(), mKernel,
            [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
            for (std::size_t i = lo; i < hi; ++i) {
                if (kind[i] != ParticleKind::GhostAir || target[i] == Real(0)) continue;
                Real weight = 0, sum = 0;
                if (i < n) {
                    if (!(zone[i] & IN_REGION) || !owned(i)) continue;
                    batch.forEachBatch(xs[i], xs.data(), mFluidLists[i], [&](PairBatch& b) {
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
                    mGrid.forEachInRadius(xs[i], R, [&](Index j, const Vec3&, Real rij) {
                        if (wanted[j] < Real(0)) return;
                        const Real w = kernel.W(rij) * sqr(airOf[j]);
                        weight += w;
                        sum += w * wanted[j];
                    });
                }
                target[i] = weight > Real(0) ? sum / weight : Real(1);
            }
            },
            64);
    }
    mTimings.airResampling += secondsSince(start);
}

void GhostSolver::fadeAir(Real span)
{
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    const auto& target = mParticles.scalarChannel(AIR_TARGET);
    // Faded in or out over one round of the phases.
    const Real rate = span / Real(mSettings.airResampleSteps);
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    bool anyRemoved = false;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::GhostAir) continue;
        weight[i] = target[i] > weight[i] ? std::min(target[i], weight[i] + rate)
                                          : std::max(target[i], weight[i] - rate);
        mParticles.masses()[i] = weight[i] * mMass;
        if (weight[i] == Real(0) && target[i] == Real(0)) remove[i] = anyRemoved = true;
    }
    if (anyRemoved) mParticles.removeIf(remove);
}

} // namespace ghost
} // namespace ghostfx
