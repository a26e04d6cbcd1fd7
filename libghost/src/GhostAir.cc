/// @file   GhostAir.cc
/// @brief  The ghost air layer of [SB12] Sec. 4.3: sampled around the liquid body, kept where it
///         still belongs, faded in and out between resamplings.
#include "ghostfx/ghost/GhostSolver.h"

#include "GhostInternal.h"

#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/PoissonSampler.h>

#include <algorithm>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

// [SB12] Sec. 4.3: ghost air ------------------------------------------------------------------

void GhostSolver::resampleAir()
{
    const auto start = std::chrono::steady_clock::now();
    prepareSolidBlocks();
    const Real R = mSettings.supportRadius();
    const Real r = PoissonSettings::SB12_RADIUS_FACTOR * mSettings.spacing;
    const double time = mTime;

    std::vector<Vec3> liquid, liquidV;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::Liquid) continue;
        liquid.push_back(mParticles.positions()[i]);
        liquidV.push_back(mParticles.velocities()[i]);
    }
    if (liquid.empty()) return;
    NeighborGrid liquidGrid(R);
    liquidGrid.build(liquid);

    // The liquid body: particles with at least one liquid neighbour. Isolated particles move
    // ballistically and get no air ([SB12] Sec. 4.5); like the solids they are obstacles the
    // new air keeps r away from. Air lives within a kernel radius of the body only, so escaped
    // spray neither attracts air nor stretches the sampling region.
    std::vector<Vec3> body, bodyV, obstacles;
    Aabb bounds;
    for (std::size_t i = 0; i < liquid.size(); ++i) {
        int n = 0;
        liquidGrid.forEachNeighbor(Index(i), [&](Index, const Vec3&, Real) { ++n; });
        if (n > 1) {
            body.push_back(liquid[i]);
            bodyV.push_back(liquidV[i]);
            bounds.expand(liquid[i]);
        } else {
            obstacles.push_back(liquid[i]);
        }
    }
    NeighborGrid bodyGrid(R);
    bodyGrid.build(body);
    auto nearBody = [&](const Vec3& x, Real* distance = nullptr) {
        return bodyGrid.nearest(x, R, [](Index) { return true; }, distance);
    };

    auto insideSolid = [&](const Vec3& x) {
        for (const auto& solid : mSolids) {
            if (solid->phi(x, time) < Real(0)) return true;
        }
        return false;
    };
    // Inside the liquid: its smoothed indicator sum_j W(x - x_j) / n0, with n0 = rho0 / m the
    // interior value, exceeds one half there (the free surface is its half level). The
    // Poisson test alone is not enough: a relaxed liquid has holes a little wider than r
    // (tests/sph/test_sampler.cc measures 1.05 - 1.1 r), and air seeded into them would sit
    // inside the liquid with p = 0, adding mass where there is no free surface.
    // Interior value n0 of sum_j W: rho0 / m once the mass is known; before (the first layer)
    // the 75th percentile of the liquid particles' own sums, which lies in the interior.
    Real n0 = 0;
    if (mMass > Real(0)) {
        n0 = mSettings.restDensity / mMass;
    } else {
        std::vector<Real> sums(liquid.size());
        parallel::forEach(0, liquid.size(), [&](std::size_t i) {
            Real sum = 0;
            liquidGrid.forEachNeighbor(Index(i), [&](Index, const Vec3&, Real rij) {
                sum += mKernel.W(rij);
            });
            sums[i] = sum;
        });
        std::nth_element(sums.begin(), sums.begin() + sums.size() * 3 / 4, sums.end());
        n0 = sums[sums.size() * 3 / 4];
    }
    // The indicator counts ghost solids too (through their blocks' grids): the thin gap between
    // liquid and a wall is not free surface, and air there would hold the liquid off the wall.
    auto insideLiquid = [&](const Vec3& x) {
        Real sum = 0;
        auto add = [&](Index, const Vec3&, Real rij) { sum += mKernel.W(rij); };
        liquidGrid.forEachInRadius(x, R, add);
        for (const SolidBlock* b : {&mStatic, &mMoving}) b->block.grid().forEachInRadius(x, R, add);
        return sum > Real(0.5) * n0;
    };

    // Keep the air that is still where the layer should be: within a kernel radius of the
    // liquid body, no closer to it than a fraction of r, outside solids and the liquid, and not
    // crowded (air advected with converging liquid bunches up: of two air particles closer than
    // that fraction of r, the later one goes). The rest fades out, and new air fades in, over the
    // steps until the next resampling: replacing the whole layer at once (as [SB12] Sec. 4.3
    // describes) makes the surface density jump by a few percent at every resampling, which with
    // the paper's soft stiffness pumps energy into the liquid; fading is the remedy [SB12]
    // Sec. 4.7 suggests.
    const Real keepDistance = mSettings.airKeepFraction * r;
    auto& target = mParticles.scalarChannel(AIR_TARGET);
    const std::size_t n = mParticles.size();
    std::vector<std::uint8_t> keep(n, 0);
    parallel::forEach(0, n, [&](std::size_t i) {
        if (mParticles.kinds()[i] != ParticleKind::GhostAir || target[i] == Real(0)) return;
        const Vec3& x = mParticles.positions()[i];
        Real d = -1;
        keep[i] = nearBody(x, &d) != INVALID_INDEX && d >= keepDistance && !insideSolid(x) &&
                  !insideLiquid(x);
    });
    if (keepDistance > Real(0)) {
        std::vector<Vec3> airX;
        std::vector<std::size_t> airIndex;
        for (std::size_t i = 0; i < n; ++i) {
            if (keep[i]) { airX.push_back(mParticles.positions()[i]); airIndex.push_back(i); }
        }
        NeighborGrid airGrid(keepDistance);
        airGrid.build(airX);
        for (std::size_t a = 0; a < airX.size(); ++a) {
            airGrid.forEachNeighbor(Index(a), [&](Index b, const Vec3&, Real) {
                if (b < a && keep[airIndex[b]]) keep[airIndex[a]] = 0;
            });
        }
    }
    std::vector<Vec3> seeds = body;
    for (std::size_t i = 0; i < n; ++i) {
        if (mParticles.kinds()[i] != ParticleKind::GhostAir) continue;
        if (keep[i]) {
            seeds.push_back(mParticles.positions()[i]);
        } else {
            // Fading air is no obstacle: the new layer cross-fades with it.
            target[i] = Real(0);
        }
    }
    // Solid particles near the layer are obstacles: the air keeps r from them.
    appendSolidPositionsInBox(bounds.padded(R + Real(2) * r), obstacles);
    if (body.empty()) {
        mTimings.airResampling += secondsSince(start);
        return;
    }

    auto accept = [&](const Vec3& x) {
        return nearBody(x) != INVALID_INDEX && !insideSolid(x) && !insideLiquid(x);
    };
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.volumeAttempts = PoissonSettings::SB12_SEEDED_ATTEMPTS;
    ps.seed = mSettings.seed ^ (0x9e3779b97f4a7c15ULL * (mStep + 1));
    const std::vector<Vec3> air =
        PoissonDiskSampler(ps).sampleFromSeeds(seeds, obstacles, accept, bounds.padded(R));

    const Index first = mParticles.addBatch(air, mMass, ParticleKind::GhostAir);
    // The very first layer is there from the start; later ones fade in.
    const bool fade = mInitialized;
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    // Ghost air velocity: the nearest liquid particle's ([SB12] Sec. 4.3).
    parallel::forEach(first, mParticles.size(), [&](std::size_t i) {
        weight[i] = fade ? Real(0) : Real(1);
        mParticles.masses()[i] = weight[i] * mMass;
        const Index j = nearBody(mParticles.positions()[i]);
        mParticles.velocities()[i] = j == INVALID_INDEX ? Vec3(0) : bodyV[j];
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
