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

BasicPressure::Channels::Channels(ParticleSet& set)
    : n(set.size())
    , x(set.positions())
    , m(set.masses())
    , rho(set.densities())
    , p(set.pressures())
    , kind(set.kinds())
    , v(set.velocities())
    , vnew(set.vectorChannel(VSTAR))
{}

void BasicPressure::accelerate(LiquidStep& step, Real dt, const Channels& ch)
{
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

    std::vector<Real> accel(ch.n, Real(0));
    parallel::forEach(
        0, ch.n,
        [&](std::size_t i) {
        if (ch.kind[i] != ParticleKind::Liquid) {
            ch.vnew[i] = ch.v[i];
            return;
        }
        const Real pi = ch.p[i] / sqr(ch.rho[i]);
        Vec3 a = g;
        lists[i].forEach([&](Index j) {
            if (j == i) return;
            const Vec3 xij = ch.x[i] - ch.x[j];
            const Real r = xij.length();
            Real term = pi + ch.p[j] / sqr(ch.rho[j]);
            const Real vx = (ch.v[i] - ch.v[j]).dot(xij);
            if (vx < Real(0)) {
                const Real nu = Real(2) * alpha * s * c / (ch.rho[i] + ch.rho[j]);
                term += -nu * vx / (r * r + Real(0.01) * s * s);
            }
            a -= ch.m[j] * term * kernel.gradW(xij, r);
        });
        for (const LiquidStep::Block b : {LiquidStep::STATIC, LiquidStep::MOVING}) {
            const Vec3* y = step.solids(b).positions().data();
            step.solidLists(b)[i].forEach([&](Index k) {
                const Vec3 xik = ch.x[i] - y[k];
                const Real r = xik.length();
                if (!(r < r0) || !(r > Real(0))) return;
                const Real q = r0 / r;
                const Real q2 = q * q, q4 = q2 * q2;
                a += (D * (q4 * q4 * q4 - q4) / (r * r)) * xik;
            });
        }
        ch.vnew[i] = ch.v[i] + dt * a;
        accel[i] = a.length();
        },
        512);
    step.setMaxAcceleration(ch.n ? *std::max_element(accel.begin(), accel.end()) : Real(0));
}

void BasicPressure::move(LiquidStep& step, Real dt, const Channels& ch)
{
    // XSPH on positions: x += dt (v + eps sum_j 2 m_j / (rho_i + rho_j) (v_j - v_i) W_ij).
    const NeighborLists& lists = step.lists();
    const CubicSplineKernel& kernel = step.kernel();
    const Real eps = step.settings().basicXsphEpsilon;
    std::vector<Vec3> xnew(ch.n);
    parallel::forEach(
        0, ch.n,
        [&](std::size_t i) {
        xnew[i] = ch.x[i];
        if (ch.kind[i] != ParticleKind::Liquid) return;
        Vec3 dv(0);
        lists[i].forEach([&](Index j) {
            if (j == i || ch.kind[j] != ParticleKind::Liquid) return;
            const Real r = (ch.x[i] - ch.x[j]).length();
            dv += (Real(2) * ch.m[j] / (ch.rho[i] + ch.rho[j]) * kernel.W(r))
                  * (ch.vnew[j] - ch.vnew[i]);
        });
        xnew[i] = ch.x[i] + dt * (ch.vnew[i] + eps * dv);
        },
        512);
    parallel::forEach(
        0, ch.n,
        [&](std::size_t i) {
        ch.x[i] = xnew[i];
        if (ch.kind[i] == ParticleKind::Liquid) ch.v[i] = ch.vnew[i];
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
    const Channels ch(step.particles());
    accelerate(step, dt, ch);
    step.timings().pressureForce += secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    move(step, dt, ch);
    step.timings().xsphAndBoundary += secondsSince(t0);
}

} // namespace ghost
} // namespace ghostfx
