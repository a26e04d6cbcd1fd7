/// @file   LevelSetGrid.h
/// @brief  Making LevelSets from OpenVDB FloatGrids, validating grids, and building level sets
///         of simple shapes (sphere, box, torus, any signed distance function).
/// @details Includes OpenVDB's grid headers: include it only where grids are created or read.
#pragma once

#include "ghostfx/sph/LevelSet.h"

#include <openvdb/openvdb.h>

#include <functional>
#include <string>

namespace ghostfx {
namespace sph {

/// Check that `grid` can serve as a level set: class GRID_LEVEL_SET, uniform cubic voxels,
/// positive background, at least one active voxel, no NaN or infinite value. Throws GridError
/// with one line naming the grid, the problem and what was expected.
void validateLevelSetGrid(const openvdb::FloatGrid& grid, const std::string& name);

/// Validate `grid` and wrap it for queries. The grid is shared, not copied, and must not change
/// while the LevelSet lives (queries read its leaf buffers directly).
/// @param name  used in error messages (defaults to the grid's own name)
LevelSet makeLevelSet(openvdb::FloatGrid::ConstPtr grid, const std::string& name = "");

/// The grid behind a LevelSet.
openvdb::FloatGrid::ConstPtr gridOf(const LevelSet& levelSet);

/// Signed distance function: negative inside (m).
using SignedDistanceFn = std::function<double(const openvdb::Vec3d&)>;

/// Narrow-band level set of an analytic signed distance function, sampled at the voxel centres
/// of `bounds` (grown by the band). Exact wherever `sdf` is a true distance.
/// @param bounds           world box that encloses the shape (m)
/// @param voxelSize        voxel edge (m)
/// @param halfWidthVoxels  narrow-band half width (voxels), OpenVDB's default is 3
openvdb::FloatGrid::Ptr levelSetFromSdf(const SignedDistanceFn& sdf, const Aabb& bounds,
                                        Real voxelSize, Real halfWidthVoxels = Real(3));

/// Exact signed distance (m) from x to the axis-aligned box [lo, hi], negative inside: the
/// building block of composed shapes (containers as max(outer, -inner), unions as min).
double boxSignedDistance(const openvdb::Vec3d& x, const openvdb::Vec3d& lo,
                         const openvdb::Vec3d& hi);

/// Sphere of `radius` (m) about `center`.
openvdb::FloatGrid::Ptr makeSphereLevelSet(const Vec3& center, Real radius, Real voxelSize,
                                           Real halfWidthVoxels = Real(3));
/// Axis-aligned box [min, max] (m).
openvdb::FloatGrid::Ptr makeBoxLevelSet(const Vec3& min, const Vec3& max, Real voxelSize,
                                        Real halfWidthVoxels = Real(3));
/// Torus about `center` in the xz-plane (axis y): ring radius `majorRadius`, tube radius
/// `minorRadius` (m).
openvdb::FloatGrid::Ptr makeTorusLevelSet(const Vec3& center, Real majorRadius, Real minorRadius,
                                          Real voxelSize, Real halfWidthVoxels = Real(3));

} // namespace sph
} // namespace ghostfx
