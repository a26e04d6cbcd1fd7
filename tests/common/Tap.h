/// @file   Tap.h
/// @brief  Test helper: the tap the emitter tests pour from, and a run to a set time.
#pragma once

#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <algorithm>

namespace ghostfx {
namespace testing {

/// An 8 x 8 x 3 cm nozzle at y = 0.47 - 0.5 m pouring downwards at 1 m/s (6.4 L/s), its
/// level set at voxels of half the spacing.
inline void addTap(ghost::GhostSolver& solver, sph::Real spacing)
{
    const sph::Real a = sph::Real(0.04);
    solver.addEmitter(
        sph::makeLevelSet(sph::makeBoxLevelSet(sph::Vec3(-a, sph::Real(0.47), -a),
                                               sph::Vec3(a, sph::Real(0.5), a), spacing / 2),
                          "tap"),
        sph::Vec3(0, -1, 0));
}

/// Step the solver with its stable steps until `duration` (s), the last step cut to land on
/// it; afterStep() runs after each step.
template <typename Fn>
void runFor(ghost::GhostSolver& solver, double duration, Fn&& afterStep)
{
    while (solver.time() < duration) {
        solver.step(std::min(solver.stableTimeStep(),
                             sph::Real(duration - solver.time()) + sph::Real(1e-7)));
        afterStep();
    }
}

} // namespace testing
} // namespace ghostfx
