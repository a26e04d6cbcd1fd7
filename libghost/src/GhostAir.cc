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
///          The layer is resampled region by region: space is cut into blocks two kernel radii
///          wide, each block belongs to one of `airResampleSteps` phases (a hash of its
///          coordinates), and step s resamples the blocks of phase s mod airResampleSteps. Every
///          part of the layer is still resampled every airResampleSteps steps ([SB12] Sec. 4.3),
///          but each step does a tenth of the work, so no step is much slower than the others.
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

int GhostSolver::airPhase(const Vec3& x) const
{
    const Real block = Real(2) * mSettings.supportRadius();
    const auto c = [block](Real v) { return std::int64_t(std::floor(v / block)); };
    std::uint64_t h = std::uint64_t(c(x[0])) * 0x9e3779b97f4a7c15ULL;
    h ^= std::uint64_t(c(x[1])) * 0xc2b2ae3d27d4eb4fULL + (h << 6) + (h >> 2);
    h ^= std::uint64_t(c(x[2])) * 0x165667b19e3779f9ULL + (h << 6) + (h >> 2);
    h ^= h >> 29;
    return int(h % std::uint64_t(mSettings.airResampleSteps));
}

void GhostSolver::resampleAir(int phase)
{
    // Needs the grid and lists of searchNeighbors() for the current positions.
    const auto start = std::chrono::steady_clock::now();
    const Real R = mSettings.supportRadius();
    const Real r = PoissonSettings::SB12_RADIUS_FACTOR * mSettings.spacing;
    const double time = mTime;
    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& kind = mParticles.kinds();
    // The region resampled now (phase < 0: everywhere), and the points within `margin` of it
    // (margin at most a block's half width: then the box corners meet every block it touches).
    auto inPhase = [&](const Vec3& q) { return phase < 0 || airPhase(q) == phase; };
    auto nearPhase = [&](const Vec3& q, Real margin) {
        if (phase < 0 || airPhase(q) == phase) return true;
        for (int c = 0; c < 8; ++c) {
            const Vec3 corner(q[0] + ((c & 1) ? margin : -margin), q[1] + ((c & 2) ? margin : -margin),
                              q[2] + ((c & 4) ? margin : -margin));
            if (airPhase(corner) == phase) return true;
        }
        return false;
    };

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
            // Only the liquid within a kernel radius of the region is asked about.
            if (kind[i] != ParticleKind::Liquid || !nearPhase(x[i], R)) continue;
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
    //    closer than r, the later one goes). The rest fades out, and new air
    //    fades in, over the steps until the next resampling: replacing the whole layer at once
    //    (as [SB12] Sec. 4.3 describes) makes the surface density jump by a few percent at
    //    every resampling, which with the paper's soft stiffness pumps energy into the liquid;
    //    fading is the remedy [SB12] Sec. 4.7 suggests.
    const Real keepDistance = mSettings.airKeepFraction * r;
    auto& target = mParticles.scalarChannel(AIR_TARGET);
    std::vector<std::uint8_t> keep(n, 0);
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] != ParticleKind::GhostAir || target[i] == Real(0) || !inPhase(x[i])) return;
        Real d = -1;
        keep[i] = nearBody(x[i], &d) != INVALID_INDEX && d >= keepDistance && !insideSolid(x[i]) &&
                  !insideLiquid(x[i]);
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
            if (kind[i] == ParticleKind::GhostAir && target[i] != Real(0) && !inPhase(x[i]) &&
                nearPhase(x[i], thinDistance)) {
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
        if (!near.contains(x[i])) continue;
        if (kind[i] == ParticleKind::GhostAir) {
            if (!inPhase(x[i]) && target[i] != Real(0)) obstacles.push_back(x[i]);
            else if (keep[i]) seeds.push_back(x[i]);
            else if (inPhase(x[i])) target[i] = Real(0);
        } else if (body[i] && indicator[i] < SURFACE_SEED_FRACTION * n0 && nearPhase(x[i], Real(2) * r)) {
            seeds.push_back(x[i]);
        } else {
            obstacles.push_back(x[i]);
        }
    }
    appendSolidPositionsInBox(near, obstacles);

    auto accept = [&](const Vec3& q) {
        return inPhase(q) && nearBody(q) != INVALID_INDEX && !insideSolid(q) && !insideLiquid(q);
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

    // 6. Density-matched weights. Each resampling adds air in the gaps the kept air leaves, so
    //    over many resamplings the layer packs ever closer (towards a maximal Poisson packing,
    //    denser than one pass of Bridson's sampler with 8 attempts): with weight 1 the air
    //    would weigh more and more, raise the density of the surface particles and push the
    //    liquid apart (a zero-gravity cube spreads within 2 s, [SB12] Fig. 4 says it must not).
    //    So the region's air aims at the weight that makes its own number density, counted
    //    with the liquid and the other air, that of the liquid interior: min(1, n0 / sigma_a),
    //    sigma_a = sum_j W(x_a - x_j). Air in a layer as dense as the liquid keeps weight 1.
    if (mMass > Real(0)) {
        const auto& xs = mParticles.positions();
        std::vector<Vec3> medium;
        for (std::size_t i = 0; i < xs.size(); ++i) {
            const ParticleKind k = mParticles.kinds()[i];
            const bool alive = k == ParticleKind::Liquid || (k == ParticleKind::GhostAir && target[i] != Real(0));
            if (alive && nearPhase(xs[i], R)) medium.push_back(xs[i]);
        }
        NeighborGrid mediumGrid(R);
        mediumGrid.build(medium);
        parallel::forEach(0, xs.size(), [&](std::size_t i) {
            if (mParticles.kinds()[i] != ParticleKind::GhostAir || target[i] == Real(0) || !inPhase(xs[i])) return;
            Real sigma = 0;
            mediumGrid.forEachInRadius(xs[i], R, [&](Index, const Vec3&, Real rij) { sigma += mKernel.W(rij); });
            target[i] = sigma > n0 ? n0 / sigma : Real(1);
        });
    }
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
