/// @file   SolidGrids.cc
#include "SolidGrids.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <openvdb/tools/GridTransformer.h>
#include <openvdb/tools/SignedFloodFill.h>

namespace ghostfx {
namespace cmd {

PlacedSolid placedSolid(const vdbio::Scene& scene, const FrameSnapshot& snapshot, std::size_t i)
{
    const vdbio::SceneSolid& solid = scene.solids[i];
    PlacedSolid placed{solid.shape};
    if (!solid.sequenceFile.empty()) {
        placed.shape = vdbio::loadLevelSet(
            vdbio::expandFramePattern(solid.sequenceFile, snapshot.frame), solid.sequenceGrid,
            msg("scene '", scene.file, "': solids[", i, "].sequence"));
    }
    if (i < snapshot.solidPlacements.size()) {
        const sph::RigidTransform& p = snapshot.solidPlacements[i];
        placed.rotation = openvdb::math::Mat3d(p.rotation);
        placed.translation = openvdb::Vec3d(p.translation);
    } else if (solid.motion.keys.empty()) {
        placed.translation = solid.velocity * snapshot.time;
    } else {
        const sph::RigidKey key = solid.motion.at(snapshot.time);
        placed.rotation = sph::KeyedMotion::rotation(key.rotateDegrees);
        placed.translation = key.translate;
    }
    return placed;
}

namespace {

/// `grid` (a level set in its solid's frame) resampled where `placed` puts that frame: a level
/// set of the same voxel size and band, its values the given distances moved.
openvdb::FloatGrid::Ptr resampled(const openvdb::FloatGrid::ConstPtr& grid,
                                  const PlacedSolid& placed)
{
    // OpenVDB's matrices act on row vectors (world = index * M): the placement x -> R x + t is
    // R transposed in the upper block and t in the last row, applied after the grid's own map.
    openvdb::math::Mat4d move = openvdb::math::Mat4d::identity();
    move.setMat3(placed.rotation.transpose());
    move.setTranslation(placed.translation);
    // A shallow copy: it shares the tree, only its transform differs.
    openvdb::FloatGrid::Ptr moved = openvdb::ConstPtrCast<openvdb::FloatGrid>(grid)->copy();
    moved->setTransform(grid->transform().copy());
    moved->transform().postMult(move);
    // Its distances sampled trilinearly over the band (resampleToMatch samples a grid that is
    // not marked a level set; marked one, it would mesh and re-voxelise it, which rounds a
    // box's edges off by 5 % of its volume at 10 voxels across), then the inside's sign
    // flood-filled from the band.
    moved->setGridClass(openvdb::GRID_UNKNOWN);
    openvdb::FloatGrid::Ptr out = openvdb::FloatGrid::create(grid->background());
    out->setTransform(openvdb::math::Transform::createLinearTransform(grid->voxelSize()[0]));
    openvdb::tools::resampleToMatch<openvdb::tools::BoxSampler>(*moved, *out);
    openvdb::tools::signedFloodFill(out->tree());
    out->setGridClass(openvdb::GRID_LEVEL_SET);
    return out;
}

} // namespace

openvdb::GridPtrVec placedSolidGrids(const vdbio::Scene& scene, const FrameSnapshot& snapshot)
{
    openvdb::GridPtrVec grids;
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const PlacedSolid placed = placedSolid(scene, snapshot, i);
        const openvdb::FloatGrid::ConstPtr grid = sph::gridOf(placed.shape);
        const bool inPlace = placed.rotation == openvdb::math::Mat3d::identity()
                             && placed.translation == openvdb::Vec3d(0.0);
        openvdb::FloatGrid::Ptr out = inPlace
                                          ? openvdb::ConstPtrCast<openvdb::FloatGrid>(grid)->copy()
                                          : resampled(grid, placed);
        out->setName(scene.solids[i].name);
        grids.push_back(out);
    }
    return grids;
}

} // namespace cmd
} // namespace ghostfx
