/// @file   PressureSolver.cc
/// @brief  The weakly compressible time step limit and the choice of model by the settings.
#include "ghostfx/ghost/PressureSolver.h"

#include "BasicPressure.h"
#include "DfsphPressure.h"
#include "TaitPressure.h"

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

std::unique_ptr<PressureSolver> makePressureSolver(const GhostSettings& settings)
{
    if (settings.method == Method::Basic) return std::make_unique<BasicPressure>();
    if (settings.pressure == PressureModel::Dfsph)
        return std::make_unique<DfsphPressure>(settings);
    return std::make_unique<TaitPressure>();
}

} // namespace ghost
} // namespace ghostfx
