/// @file   SolidGrids.h
/// @brief  The scene's solids where they are at a frame: each one's shape (its per-frame file
///         for a deforming solid) and placement, for the preview and for the volume file's
///         solid grids (outputs.volume.solids).
#pragma once

#include "FrameWriter.h"

#include <ghostfx/sph/LevelSet.h>

#include <openvdb/openvdb.h>

namespace ghostfx {
namespace cmd {

/// A solid at a frame: its level set in its own frame and where that frame sits.
struct PlacedSolid
{
    sph::LevelSet shape;
    openvdb::math::Mat3d rotation = openvdb::math::Mat3d::identity();
    openvdb::Vec3d translation{0.0};
};

/// Solid `i` of the scene at the snapshot's time: the solver's placement where the snapshot
/// has it (dynamic bodies, steered solids), else the scene's velocity or keys.
PlacedSolid placedSolid(const vdbio::Scene& scene, const FrameSnapshot& snapshot, std::size_t i);

/// Every solid's level set resampled where it is (its distances sampled trilinearly by
/// openvdb::tools::resampleToMatch, the inside flood-filled), on an axis-aligned grid of the
/// shape's voxel size, named after the solid; a solid that stands where its shape is given keeps its grid as it is.
openvdb::GridPtrVec placedSolidGrids(const vdbio::Scene& scene, const FrameSnapshot& snapshot);

} // namespace cmd
} // namespace ghostfx
