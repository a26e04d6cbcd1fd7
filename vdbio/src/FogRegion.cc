/// @file   FogRegion.cc
/// @brief  A fog volume's region (density above a threshold) as a level set, so a gas source can
///         be given as the density grid a TD already has. Its own translation unit: the
///         morphology and filters of TopologyToLevelSet are heavy to compile (STACK.md).
#include "FogRegion.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <openvdb/tools/TopologyToLevelSet.h>

namespace ghostfx {
namespace vdbio {

sph::LevelSet fogRegionToLevelSet(const openvdb::FloatGrid& fog, float threshold,
                                  const std::string& name)
{
    // Active voxels of the mask: the fog's voxels denser than the threshold.
    openvdb::MaskGrid mask(false);
    mask.setTransform(fog.transform().copy());
    auto acc = mask.getAccessor();
    std::size_t inside = 0;
    for (auto it = fog.cbeginValueOn(); it; ++it) {
        if (!(*it > threshold)) continue;
        if (it.isVoxelValue()) {
            acc.setValueOn(it.getCoord());
            ++inside;
        } else {
            openvdb::CoordBBox box;
            it.getBoundingBox(box);
            mask.tree().fill(box, true, true);
            inside += box.volume();
        }
    }
    if (inside == 0) {
        throw GridError(msg("grid '", name, "': no voxel of the fog volume exceeds the threshold ",
                            threshold, ", so the region is empty"));
    }
    // One closing step fills pinholes; one smoothing pass takes the voxel staircase off.
    openvdb::FloatGrid::Ptr sdf =
        openvdb::tools::topologyToLevelSet(mask, /*halfWidth=*/3, /*closing=*/1,
                                           /*dilation=*/0, /*smoothing=*/1);
    sdf->setName(name);
    return sph::makeLevelSet(sdf, name);
}

} // namespace vdbio
} // namespace ghostfx
