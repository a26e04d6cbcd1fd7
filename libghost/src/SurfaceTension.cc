/// @file   SurfaceTension.cc
/// @brief  The continuum surface force over the liquid and its ghost air (SurfaceTension.h).
#include "SurfaceTension.h"

#include "GhostInternal.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>

#include <cmath>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

namespace {

/// Liquid and ghost air: the two phases of the colour field.
bool phase(ParticleKind kind)
{
    return kind == ParticleKind::Liquid || kind == ParticleKind::GhostAir;
}

} // namespace

Real SurfaceTension::capillaryTimeStep(const GhostSettings& settings)
{
    const double h = double(settings.spacing);
    return Real(std::sqrt(double(settings.restDensity) * h * h * h
                          / (2 * M_PI * double(settings.surfaceTension))));
}

void SurfaceTension::colourGradients(LiquidStep& step)
{
    const ParticleSet& set = step.particles();
    const std::size_t n = set.size();
    const auto& kind = set.kinds();
    const auto& x = set.positions();
    const auto& m = set.masses();
    const auto& rho = set.densities();
    const CubicSplineKernel& kernel = step.kernel();
    const Real reliable = Real(0.01) / step.settings().spacing;
    mNormal.assign(n, Vec3(0));
    mReliable.assign(n, 0);
    // Air sampled after the step's search has no list (and no weight yet): it stays out.
    const std::size_t listed = step.lists().size();
    // The air's share of the colour field is its volume as sampled, M / rho0, times how far
    // it has faded in (AIR_FADE): not its mass, which the air's weights scale to complete the
    // liquid's density and which drifts (a drop's air lost 17 % of its mass in 0.2 s, and its
    // l = 2 oscillation ran 21-25 % slow with that mass as the colour).
    const auto& fade = set.scalarChannel(AIR_FADE);
    const Real airVolume = step.particleMass() / step.settings().restDensity;
    parallel::forEach(
        0, listed,
        [&](std::size_t i) {
        if (!phase(kind[i])) return;
        const Real ci = kind[i] == ParticleKind::Liquid ? Real(1) : Real(0);
        Vec3 sum(0);
        for (Index j : step.lists()[i]) {
            if (!phase(kind[j])) continue;
            const bool liquid = kind[j] == ParticleKind::Liquid;
            const Real cj = liquid ? Real(1) : Real(0);
            if (cj == ci) continue;
            const Vec3 xij = x[i] - x[j];
            const Real volume = liquid ? m[j] / rho[j] : fade[j] * airVolume;
            sum += xij * ((cj - ci) * volume * kernel.gradFactor(xij.length()));
        }
        mNormal[i] = sum;
        mReliable[i] = sum.length() > reliable;
        },
        512);
}

void SurfaceTension::apply(LiquidStep& step, Real dt)
{
    if (step.exchange()) {
        throw ValueError("liquid setting surface_tension: the surface tension runs on one "
                         "process; run this scene without MPI");
    }
    colourGradients(step);
    ParticleSet& set = step.particles();
    const auto& kind = set.kinds();
    const auto& x = set.positions();
    const auto& m = set.masses();
    const auto& rho = set.densities();
    auto& w = set.vectorChannel(VSTAR);
    const CubicSplineKernel& kernel = step.kernel();
    const double sigma = double(step.settings().surfaceTension);
    const auto& fade = set.scalarChannel(AIR_FADE);
    const Real airVolume = step.particleMass() / step.settings().restDensity;
    parallel::forEach(
        0, step.lists().size(),
        [&](std::size_t i) {
        if (kind[i] != ParticleKind::Liquid || !mReliable[i]) return;
        const Vec3 ni = mNormal[i] / mNormal[i].length();
        double divergence = 0, moment = 0;
        for (Index j : step.lists()[i]) {
            if (j == i || !phase(kind[j]) || !mReliable[j]) continue;
            const Vec3 xij = x[i] - x[j];
            const Real volume =
                kind[j] == ParticleKind::Liquid ? m[j] / rho[j] : fade[j] * airVolume;
            const Real f = kernel.gradFactor(xij.length());
            const Vec3 nj = mNormal[j] / mNormal[j].length();
            divergence += double(volume * f * (nj - ni).dot(xij));
            moment += double(volume * f * xij.lengthSqr());
        }
        if (!(moment < 0)) return;
        const double kappa = -(3.0 / -moment) * divergence;
        // The colour gradient's integral across the layer falls half on the liquid's side and
        // half on the air's (a symmetric kernel over a step); the air carries no force, so the
        // liquid takes the whole (measured: with one share the drops held 48-51 % of Laplace).
        w[i] += mNormal[i] * Real(2 * double(dt) * sigma * kappa / double(rho[i]));
        },
        512);
}

} // namespace ghost
} // namespace ghostfx
