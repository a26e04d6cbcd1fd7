/// @file   TaitPressure.cc
/// @brief  The Tait step of [SB12] Algorithm 3: density, the equation of state (Sec. 3,
///         Monaghan 1994), and the pressure force summed over every neighbour, liquid, air and
///         ghost solid, whose pressure is its nearest liquid particle's (lines 5-7).
#include "TaitPressure.h"

#include "GhostInternal.h"

#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>

#include <algorithm>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

bool TaitEquationOfState::pressureFromDensity(LiquidStep& step)
{
    ParticleSet& set = step.particles();
    const auto& rho = set.densities();
    auto& p = set.pressures();
    const Real rho0 = step.settings().restDensity, k = step.settings().stiffness;
    parallel::forEach(
        0, set.size(), [&](std::size_t i) { p[i] = taitPressure(rho[i], rho0, k); }, 2048);
    return true;
}

void TaitPressure::accelerate(LiquidStep& step, Real dt, std::vector<Vec3>& gradMass)
{
    ParticleSet& set = step.particles();
    const std::size_t n = set.size();
    const auto& x = set.positions();
    const auto& m = set.masses();
    const auto& rho = set.densities();
    const auto& p = set.pressures();
    const auto& kind = set.kinds();
    const auto& v = set.velocities();
    auto& vstar = set.vectorChannel(VSTAR);
    const NeighborLists& lists = step.lists();
    const Vec3 g = step.settings().gravity;
    const Real M = step.particleMass();
    const bool shifting = !gradMass.empty();
    const Real* halo = step.haloFlags();
    resizeStepArray(mTerm, n);
    parallel::forEach(
        0, n, [&](std::size_t i) { mTerm[i] = p[i] / sqr(rho[i]); }, 2048);
    std::vector<Real> accel(n, Real(0));
    forRangeWithBatch(
        n, step.kernel(),
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (kind[i] != ParticleKind::Liquid || (halo && halo[i] != Real(0))) {
                vstar[i] = v[i]; // a halo copy's comes from its owner (refresh)
                continue;
            }
            const Vec3 xi = x[i];
            const Real pi = mTerm[i];
            // The particle itself is in its list: r = 0 gives grad W = 0.
            Vec3 a = g;
            batch.forEachBatch(xi, x.data(), lists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]] * (pi + mTerm[b.j[k]]);
                for (int k = 0; k < b.n; ++k) b.f[k] *= -kernel.gradFactor(b.r[k]);
                a += b.sumScaledOffsets(b.f);
                if (shifting) {
                    for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]] * kernel.gradFactor(b.r[k]);
                    gradMass[i] += b.sumScaledOffsets(b.f);
                }
            });
            for (const LiquidStep::Block block : {LiquidStep::STATIC, LiquidStep::MOVING}) {
                // p / rho^2 of a ghost solid from its nearest liquid particle's values (lines
                // 5-7), computed here: solid pairs are a few percent of all, and an array of
                // it for every solid particle cost 4 bytes each (bench/history/diary-2026-11.md,
                // "Memory: the lists' ends").
                const ParticleSet& solids = step.solids(block);
                const Real* pS = solids.pressures().data();
                const Real* rhoS = solids.densities().data();
                batch.forEachBatch(xi, solids.positions().data(), step.solidLists(block)[i],
                                   [&](PairBatch& b) {
                    for (int k = 0; k < b.n; ++k)
                        b.f[k] = M * (pi + pS[b.j[k]] / sqr(rhoS[b.j[k]]));
                    for (int k = 0; k < b.n; ++k) b.f[k] *= -kernel.gradFactor(b.r[k]);
                    a += b.sumScaledOffsets(b.f);
                    if (shifting) {
                        for (int k = 0; k < b.n; ++k) b.f[k] = M * kernel.gradFactor(b.r[k]);
                        gradMass[i] += b.sumScaledOffsets(b.f);
                    }
                });
            }
            vstar[i] = v[i] + dt * a;
            accel[i] = a.length();
        }
        },
        512);
    // A process whose slab has no particles left still takes part in the exchange below.
    step.setMaxAcceleration(n ? *std::max_element(accel.begin(), accel.end()) : Real(0));
}

void TaitPressure::step(LiquidStep& step, Real dt)
{
    step.searchAndDensity();
    const auto t0 = std::chrono::steady_clock::now();
    // Particle shifting needs grad C = sum_j (m_j / rho0) grad W_ij over the same pairs.
    const bool shifting = step.settings().shifting() > Real(0);
    std::vector<Vec3> gradMass(shifting ? step.particles().size() : 0, Vec3(0));
    accelerate(step, dt, gradMass);
    step.timings().pressureForce += secondsSince(t0);
    step.applySurfaceTension(dt);
    step.applyViscosity(dt);
    if (ParticleExchange* exchange = step.exchange()) {
        const auto t = std::chrono::steady_clock::now();
        step.setMaxAcceleration(Real(exchange->maxOf(double(step.maxAcceleration()))));
        exchange->refresh(step.particles(), {VSTAR});
        step.timings().exchange += secondsSince(t);
    }
    step.finish(dt, gradMass);
}

} // namespace ghost
} // namespace ghostfx
