/// @file   PointGridBuild.h
/// @brief  What the points writers share (PointsFile.cc, WhitewaterFile.cc): a PointDataGrid
///         built from world positions, and attributes routed into it in the positions' order.
#pragma once

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {
namespace detail {

/// A PointDataGrid and the index grid that routes attribute values to its points.
struct PointGridBuild
{
    openvdb::points::PointDataGrid::Ptr grid;
    openvdb::tools::PointIndexGrid::Ptr index;
};

/// The points at world `positions` (double, so the world-to-voxel conversion adds no rounding
/// of its own) in a grid of `voxelSize`, "P" stored as float offsets from the voxel centres
/// without compression (PointsFile.cc).
PointGridBuild buildPointGrid(const std::vector<openvdb::Vec3d>& positions, double voxelSize);

/// Append attribute `name` of type T holding `data` (one value per point, in the order of the
/// positions the grid was built from) and route it through the index grid like "P".
template <typename T>
void addAttribute(PointGridBuild& build, const std::string& name, const std::vector<T>& data)
{
    using openvdb::points::PointDataTree;
    using openvdb::tools::PointIndexTree;
    openvdb::points::appendAttribute<T>(build.grid->tree(), name);
    openvdb::points::populateAttribute<PointDataTree, PointIndexTree,
                                       openvdb::points::PointAttributeVector<T>>(
        build.grid->tree(), build.index->tree(), name,
        openvdb::points::PointAttributeVector<T>(data));
}

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
