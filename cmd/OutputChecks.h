/// @file   OutputChecks.h
/// @brief  Every output option of a scene checked against the simulation it runs, before the
///         first step: an error costs no simulated frame and leaves no file behind.
#pragma once

#include "Simulation.h"

#include <ghostfx/vdbio/Scene.h>

#include <string>

namespace ghostfx {
namespace cmd {

/// Refuse, with one line naming the scene and the key, what the frame writer would refuse
/// after the first frame: a points channel or a volume grid the medium's particles do not
/// carry (`outputs.points.channels`, `outputs.volume.grids` and their gas twins), a preview
/// grid no volume output builds (`outputs.preview.grid`), a mesh of a scene with no liquid
/// (`outputs.mesh`), and bad output options.
void checkOutputs(const vdbio::Scene& scene, const Simulation& sim);

/// Refuse an output whose file pattern points into a folder of the output folder `folder`
/// that does not exist or cannot be written (`outputs.mesh.file`), before the first step.
void checkOutputFolders(const vdbio::Scene& scene, const std::string& folder);

} // namespace cmd
} // namespace ghostfx
