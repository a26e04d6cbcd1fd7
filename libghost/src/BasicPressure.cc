/// @file   BasicPressure.cc
/// @brief  The "Basic SPH" baseline of [SB12] Sec. 3, the method Ghost SPH is compared with:
///         density summed over liquid only, Tait pressure, Becker and Teschner 2007 artificial
///         viscosity (alpha = 0.0005), Lennard-Jones repulsion from solid particles (Monaghan
///         1994) and XSPH on the position update (Monaghan 1989, epsilon = 0.5).
/// @details Uses the step's neighbour lists like Ghost SPH (LiquidStep): the boundary
///          particles act only through the Lennard-Jones force, from the solid blocks' lists.
#include "BasicPressure.h"

#include "GhostInternal.h"

#include <ghostfx/sph/Parallel.h>

#include <algorithm>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

void BasicPressure::accelerate(LiquidStep& step, Real dt)
{
    ParticleSet& set = step.particles();
    const std::size_t n = set.size();
    const auto& x = set.positions();
    const auto& m = set.masses();
    const auto& rho = set.densities();
    const auto& p = set.pressures();
    const auto& kind = set.kinds();
    const auto& v = set.velocities();
    auto& vnew = set.vectorChannel(VSTAR);
    const GhostSettings& settings = step.settings();
    const NeighborLists& lists = step.lists();
    const CubicSplineKernel& kernel = step.kernel();
    const Vec3 g = settings.gravity;
    const Real c = settings.soundSpeed();
    // Becker and Teschner 2007, Eq. 11: Pi_ij = -nu min(v_ij . x_ij, 0) / (|x_ij|^2 + 0.01 s^2),
    // nu = 2 alpha s c / (rho_i + rho_j), with s the smoothing length (half the support).
    const Real s = Real(0.5) * settings.supportRadius();
    const Real alpha = settings.basicViscosityAlpha;
    // Monaghan 1994, Eq. 4.3: f = D ((r0 / r)^12 - (r0 / r)^4) x_ij / r^2 for r < r0. Liquid
    // starts half a spacing from solid surfaces (GhostSolver::addLiquid), where the boundary's
    // surface particles sit, so r0 = h / 2: repulsion begins only closer than that.
    const Real r0 = Real(0.5) * settings.spacing;
    const Real D = step.lennardJones();

    std::vector<Real> accel(n, Real(0));
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        if (kind[i] != ParticleKind::Liquid) {
            vnew[i] = v[i];
            return;
        }
        const Real pi = p[i] / sqr(rho[i]);
        Vec3 a = g;
        lists[i].forEach([&](Index j) {
            if (j == i) return;
            const Vec3 xij = x[i] - x[j];
            const Real r = xij.length();
            Real term = pi + p[j] / sqr(rho[j]);
            const Real vx = (v[i] - v[j]).dot(xij);
            if (vx < Real(0)) {
                const Real nu = Real(2) * alpha * s * c / (rho[i] + rho[j]);
                term += -nu * vx / (r * r + Real(0.01) * s * s);
            }
            a -= m[j] * term * kernel.gradW(xij, r);
        });
        for (const LiquidStep::Block b : {LiquidStep::STATIC, LiquidStep::MOVING}) {
            const Vec3* y = step.solids(b).positions().data();
            step.solidLists(b)[i].forEach([&](Index k) {
                const Vec3 xik = x[i] - y[k];
                const Real r = xik.length();
                if (!(r < r0) || !(r > Real(0))) return;
                const Real q = r0 / r;
                const Real q2 = q * q, q4 = q2 * q2;
                a += (D * (q4 * q4 * q4 - q4) / (r * r)) * xik;
            });
        }
        vnew[i] = v[i] + dt * a;
        accel[i] = a.length();
        },
        512);
    step.setMaxAcceleration(n ? *std::max_element(accel.begin(), accel.end()) : Real(0));
}

void BasicPressure::move(LiquidStep& step, Real dt)
{
    // XSPH on positions: x += dt (v + eps sum_j 2 m_j / (rho_i + rho_j) (v_j - v_i) W_ij).
    ParticleSet& set = step.particles();
    const std::size_t n = set.size();
    const auto& x = set.positions();
    const auto& m = set.masses();
    const auto& rho = set.densities();
    const auto& kind = set.kinds();
    auto& v = set.velocities();
    const auto& vnew = set.vectorChannel(VSTAR);
    const NeighborLists& lists = step.lists();
    const CubicSplineKernel& kernel = step.kernel();
    const Real eps = step.settings().basicXsphEpsilon;
    auto& xw = set.positions();
    std::vector<Vec3> xnew(n);
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        xnew[i] = x[i];
        if (kind[i] != ParticleKind::Liquid) return;
        Vec3 dv(0);
        lists[i].forEach([&](Index j) {
            if (j == i || kind[j] != ParticleKind::Liquid) return;
            const Real r = (x[i] - x[j]).length();
            dv += (Real(2) * m[j] / (rho[i] + rho[j]) * kernel.W(r)) * (vnew[j] - vnew[i]);
        });
        xnew[i] = x[i] + dt * (vnew[i] + eps * dv);
        },
        512);
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        xw[i] = xnew[i];
        if (kind[i] == ParticleKind::Liquid) v[i] = vnew[i];
        },
        4096);
}

void BasicPressure::step(LiquidStep& step, Real dt)
{
    // The density over liquid only: the boundary particles act through Lennard-Jones forces.
    DensityPass pass;
    pass.solids = false;
    step.searchAndDensity(pass);
    auto t0 = std::chrono::steady_clock::now();
    accelerate(step, dt);
    step.timings().pressureForce += secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    move(step, dt);
    step.timings().xsphAndBoundary += secondsSince(t0);
}

} // namespace ghost
} // namespace ghostfx
