/// @file   PressureSolver.cc
/// @brief  The weakly compressible time step limit and the choice of model by the settings.
#include "ghostfx/ghost/PressureSolver.h"

#include "BasicPressure.h"
#include "DfsphPressure.h"
#include "TaitPressure.h"

#include <ghostfx/ghost/LiquidStep.h>
#include <ghostfx/sph/Parallel.h>

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace ghost {

Real PressureSolver::stableTimeStep(const GhostSettings& settings, Real fastest,
                                    Real maxAcceleration) const
{
    // Acoustic CFL: dt <= cfl h / (c + |v|max).
    const Real h = settings.spacing;
    Real dt = settings.cflNumber * h / (settings.soundSpeed() + fastest);
    // Force limit (Monaghan 1992): dt <= cfl sqrt(h / |a|max), with the largest acceleration
    // of the last step (gravity before the first), which covers stiff Lennard-Jones walls.
    const Real a = std::max(maxAcceleration, settings.gravity.length());
    if (a > Real(0)) dt = std::min(dt, settings.cflNumber * std::sqrt(h / a));
    return dt;
}

void PressureSolver::solidPairPressure(LiquidStep& step, SolidPairPressure& out) const
{
    const sph::ParticleSet& set = step.particles();
    const auto& kind = set.kinds();
    const auto& p = set.pressures();
    const auto& rho = set.densities();
    out.liquid.resize(set.size());
    parallel::forEach(
        0, set.size(),
        [&](std::size_t i) {
        out.liquid[i] = kind[i] == sph::ParticleKind::Liquid ? p[i] / (rho[i] * rho[i]) : Real(0);
        },
        4096);
    out.share = 1;
    out.solid = SolidPairPressure::SolidTerm::Own;
    out.wallGravity = nullptr;
}

std::unique_ptr<PressureSolver> makePressureSolver(const GhostSettings& settings)
{
    if (settings.method == Method::Basic) return std::make_unique<BasicPressure>();
    if (settings.pressure == PressureModel::Dfsph)
        return std::make_unique<DfsphPressure>(settings);
    return std::make_unique<TaitPressure>();
}

} // namespace ghost
} // namespace ghostfx
