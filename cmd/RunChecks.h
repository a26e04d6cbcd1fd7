/// @file   RunChecks.h
/// @brief  What `ghostfx run` checks of a simulation before its first step: a scene that would
///         not finish (CFL steps too short to ever end a frame), and one that will run but not
///         as its author expects (a fixed step beyond the stability limit, walls thinner than
///         the kernel support), warned about in one line each; `--quiet` keeps the warnings.
#pragma once

#include "Simulation.h"

#include <ghostfx/vdbio/Scene.h>

#include <string>

namespace ghostfx {
namespace cmd {

/// The most steps a frame may take: what settings.substeps allows.
constexpr double MAX_STEPS_PER_FRAME = 100000;

/// The scene keys that set a simulation's time step and stiffness ("settings.substeps,
/// settings.cfl, settings.stiffness"; the gas's in settings.gas), for messages.
std::string stepKeys(const vdbio::Scene& scene);

/// Refuse CFL steps so short at the start that a frame would take more than
/// MAX_STEPS_PER_FRAME of them (a stiffness of 1e19 Pa: 1e-10 s steps), naming the keys.
void checkStepsPerFrame(const vdbio::Scene& scene, const Simulation& sim);

/// A fixed step far beyond the stability limit blows up within a few steps, after a frame or
/// more of output: say so (where `prints`) with both numbers and the substeps that would hold.
/// Collective over the processes of a distributed run (the limit is every process's).
void warnFixedStepBeyondTheLimit(const vdbio::Scene& scene, const Simulation& sim, bool prints);

/// A solid thinner than the kernel support `depth` (m) holds too few ghost solids (or boundary
/// particles): liquid beside it is under-dense, and a stiff liquid sticks to it. Each static
/// solid is judged as part of the union of the static solids (a ramp lying on a floor is as
/// thick as both, and its face against the floor is not reached by liquid); a moving one alone.
/// Nothing for `depth` 0 (a scene whose solids are not sampled so).
void warnThinSolids(const vdbio::Scene& scene, double depth);

} // namespace cmd
} // namespace ghostfx
