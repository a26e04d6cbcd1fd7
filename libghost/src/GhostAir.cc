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
#include "ghostfx/ghost/GhostSolver.h"

#include "GhostInternal.h"

#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/PoissonSampler.h>

#include <algorithm>

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

void GhostSolver::resampleAir()
{
    // Needs the grid and lists of searchNeighbors() for the current positions.
    const auto start = std::chrono::steady_clock::now();
    const Real R = mSettings.supportRadius();
    const Real r = PoissonSettings::SB12_RADIUS_FACTOR * mSettings.spacing;
    const double time = mTime;
    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& kind = mParticles.kinds();

    // 1. Per liquid particle: its liquid-and-solid indicator sum_j W_ij (ghost solids count:
    //    the thin gap between liquid and a wall is not free surface, and air there would hold
    //    the liquid off the wall) and whether it has a liquid neighbour. Particles without one
    //    move ballistically and get no air ([SB12] Sec. 4.5): like the solids they are
    //    obstacles the new air keeps r away from. Air lives within a kernel radius of the body
    //    only, so escaped spray neither attracts air nor stretches the sampling region.
    std::vector<Real> indicator(n, Real(0));
    std::vector<std::uint8_t> body(n, 0);
    parallel::forRange(0, n, [&](std::size_t lo, std::size_t hi) {
        const CubicSplineKernel kernel = mKernel;
        PairBatch batch;
        for (std::size_t i = lo; i < hi; ++i) {
            if (kind[i] != ParticleKind::Liquid) continue;
            Real sum = 0;
            int liquidNeighbours = 0;
            batch.forEachBatch(x[i], x.data(), mFluidLists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = Real(kind[b.j[k]] == ParticleKind::Liquid);
                for (int k = 0; k < b.n; ++k) liquidNeighbours += int(b.f[k]);
                for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]);
                sum += b.sum(b.f);
            });
            for (const SolidBlock* block : {&mStatic, &mMoving}) {
                batch.forEachBatch(x[i], block->block.particles().positions().data(), block->lists[i],
                                   [&](PairBatch& b) {
                    for (int k = 0; k < b.n; ++k) b.f[k] = kernel.W(b.r[k]);
                    sum += b.sum(b.f);
                });
            }
            indicator[i] = sum;
            body[i] = liquidNeighbours > 1;
        }
    }, 512);
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
        return mGrid.nearest(q, R, [&](Index j) { return body[j] != 0; }, distance);
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
            if (kind[i] == ParticleKind::Liquid) sums.push_back(indicator[i]);
        }
        std::nth_element(sums.begin(), sums.begin() + sums.size() * 3 / 4, sums.end());
        n0 = sums[sums.size() * 3 / 4];
    }
    auto insideLiquid = [&](const Vec3& q) {
        Real sum = 0;
        mGrid.forEachInRadius(q, R, [&](Index j, const Vec3&, Real rij) {
            if (kind[j] == ParticleKind::Liquid) sum += mKernel.W(rij);
        });
        for (const SolidBlock* b : {&mStatic, &mMoving}) {
            b->block.grid().forEachInRadius(q, R, [&](Index, const Vec3&, Real rij) { sum += mKernel.W(rij); });
        }
        return sum > Real(0.5) * n0;
    };

    // 3. Keep the air that is still where the layer should be: within a kernel radius of the
    //    liquid body, no closer to it than a fraction of r, outside solids and the liquid, and
    //    not crowded (air advected with converging liquid bunches up: of two air particles
    //    closer than that fraction of r, the later one goes). The rest fades out, and new air
    //    fades in, over the steps until the next resampling: replacing the whole layer at once
    //    (as [SB12] Sec. 4.3 describes) makes the surface density jump by a few percent at
    //    every resampling, which with the paper's soft stiffness pumps energy into the liquid;
    //    fading is the remedy [SB12] Sec. 4.7 suggests.
    const Real keepDistance = mSettings.airKeepFraction * r;
    auto& target = mParticles.scalarChannel(AIR_TARGET);
    std::vector<std::uint8_t> keep(n, 0);
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] != ParticleKind::GhostAir || target[i] == Real(0)) return;
        Real d = -1;
        keep[i] = nearBody(x[i], &d) != INVALID_INDEX && d >= keepDistance && !insideSolid(x[i]) &&
                  !insideLiquid(x[i]);
    });
    if (keepDistance > Real(0)) {
        std::vector<Vec3> airX;
        std::vector<std::size_t> airIndex;
        for (std::size_t i = 0; i < n; ++i) {
            if (keep[i]) {
                airX.push_back(x[i]);
                airIndex.push_back(i);
            }
        }
        NeighborGrid airGrid(keepDistance);
        airGrid.build(airX);
        for (std::size_t a = 0; a < airX.size(); ++a) {
            airGrid.forEachNeighbor(Index(a), [&](Index b, const Vec3&, Real) {
                if (b < a && keep[airIndex[b]]) keep[airIndex[a]] = 0;
            });
        }
    }

    // 4. Seeds: the body's particles near the free surface and the kept air; obstacles: the
    //    rest of the liquid and the solid particles near the layer. Fading air is no obstacle:
    //    the new layer cross-fades with it.
    std::vector<Vec3> seeds, obstacles;
    for (std::size_t i = 0; i < n; ++i) {
        if (kind[i] == ParticleKind::GhostAir) {
            if (keep[i]) seeds.push_back(x[i]);
            else target[i] = Real(0);
        } else if (body[i] && indicator[i] < SURFACE_SEED_FRACTION * n0) {
            seeds.push_back(x[i]);
        } else {
            obstacles.push_back(x[i]);
        }
    }
    appendSolidPositionsInBox(bounds.padded(R + Real(2) * r), obstacles);

    auto accept = [&](const Vec3& q) {
        return nearBody(q) != INVALID_INDEX && !insideSolid(q) && !insideLiquid(q);
    };
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.volumeAttempts = PoissonSettings::SB12_SEEDED_ATTEMPTS;
    ps.seed = mSettings.seed ^ (0x9e3779b97f4a7c15ULL * (mStep + 1));
    const std::vector<Vec3> air =
        PoissonDiskSampler(ps).sampleFromSeeds(seeds, obstacles, accept, bounds.padded(R));

    // 5. The new air: faded in from weight 0 (the very first layer is there from the start),
    //    with the velocity of the nearest body particle ([SB12] Sec. 4.3).
    const Index first = mParticles.addBatch(air, mMass, ParticleKind::GhostAir);
    const bool fade = mInitialized;
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    auto& v = mParticles.velocities();
    parallel::forEach(first, mParticles.size(), [&](std::size_t i) {
        weight[i] = fade ? Real(0) : Real(1);
        mParticles.masses()[i] = weight[i] * mMass;
        const Index j = nearBody(mParticles.positions()[i]);
        v[i] = j == INVALID_INDEX ? Vec3(0) : v[j];
        mParticles.densities()[i] = mSettings.restDensity;
    });
    mTimings.airResampling += secondsSince(start);
}

void GhostSolver::fadeAir()
{
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    const auto& target = mParticles.scalarChannel(AIR_TARGET);
    const Real rate = Real(1) / Real(mSettings.airResampleSteps);
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
