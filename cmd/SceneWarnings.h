/// @file   SceneWarnings.h
/// @brief  What `ghostfx run` warns about before the first step: a scene that will run, but
///         not as its author expects (a fixed step beyond the stability limit, walls thinner
///         than the kernel support). One line each on stderr; `--quiet` keeps them.
#pragma once

#include "Simulation.h"

#include <ghostfx/vdbio/Scene.h>

namespace ghostfx {
namespace cmd {

/// A fixed step far beyond the stability limit blows up within a few steps, after a frame or
/// more of output: say so with both numbers and the substeps that would hold.
void warnFixedStepBeyondTheLimit(const vdbio::Scene& scene, const Simulation& sim);

/// A solid thinner than the kernel support `depth` (m) holds too few ghost solids (or boundary
/// particles): liquid beside it is under-dense, and a stiff liquid sticks to it. Each static
/// solid is judged as part of the union of the static solids (a ramp lying on a floor is as
/// thick as both, and its face against the floor is not reached by liquid); a moving one alone.
/// Nothing for `depth` 0 (a scene whose solids are not sampled so).
void warnThinSolids(const vdbio::Scene& scene, double depth);

} // namespace cmd
} // namespace ghostfx
