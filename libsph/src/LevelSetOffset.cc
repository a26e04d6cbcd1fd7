/// @file   LevelSetOffset.cc
/// @brief  erodedLevelSet: a level set's inner parallel surface, as a new narrow band.
/// @details Its own translation unit: OpenVDB's rebuild (mesh extraction and re-voxelisation)
///          is one of the slow headers to compile (STACK.md, "Compile times").
#include "ghostfx/sph/LevelSetGrid.h"

#include "ghostfx/sph/Exceptions.h"

#include <openvdb/tools/LevelSetRebuild.h>

namespace ghostfx {
namespace sph {

LevelSet erodedLevelSet(const LevelSet& shape, Real depth)
{
    const std::string& name = shape.name();
    const Real voxel = shape.voxelSize();
    // The surface phi = -depth must lie inside the band with half a voxel to spare, so that
    // the values on both sides of it are distances, not the clamp.
    const Real deepest = shape.bandWidth() - Real(0.5) * voxel;
    if (!(depth >= Real(0)) || depth > deepest) {
        throw ValueError(msg("level set '", name, "': cannot erode it by ", depth,
                             " m: expected 0 to its band width less half a voxel (", deepest,
                             " m)"));
    }
    const openvdb::FloatGrid::ConstPtr grid = gridOf(shape);
    const float halfWidthVoxels = float(shape.bandWidth() / voxel);
    openvdb::FloatGrid::Ptr eroded =
        openvdb::tools::levelSetRebuild(*grid, float(-depth), halfWidthVoxels, halfWidthVoxels);
    eroded->setName(grid->getName());
    if (eroded->activeVoxelCount() == 0) {
        throw ValueError(msg("level set '", name, "': nothing is left of it ", depth,
                             " m inside its surface: expected a shape thicker than ", 2 * depth,
                             " m"));
    }
    return makeLevelSet(eroded, name);
}

} // namespace sph
} // namespace ghostfx
