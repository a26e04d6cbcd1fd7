/// @file   MaskDilation.h
/// @brief  Dilation of a mask in the max norm, in three separable passes instead of k
///         26-neighbour iterations.
/// @details Growing every active voxel into the cube of side 2 k + 1 about it is what k
///          iterations of tools::dilateActiveValues(mask, k, NN_FACE_EDGE_VERTEX) do; the
///          cube is the product of three segments, so one pass along each axis gives the same
///          voxels. A pass works on a leaf's 512-bit mask as OpenVDB stores it (eight 64-bit
///          words, one per x; in a word, one byte per y; in a byte, one bit per z): along x
///          it ORs neighbouring words, along y shifted words, along z shifted bits within the
///          bytes, taking the bits that cross a leaf face from the neighbouring leaf.
#pragma once

#include <openvdb/openvdb.h>

namespace ghostfx {
namespace vdbio {

/// Adds to `mask` every voxel within max-norm distance `k` (voxels, >= 0) of an active voxel.
/// Active tiles are voxelised first (a mask built voxel by voxel has none). Multi-threaded;
/// the result does not depend on the thread count.
void dilateMaxNorm(openvdb::MaskTree& mask, int k);

/// Adds to `mask` the six face neighbours of every active voxel: one iteration of
/// tools::dilateActiveValues(mask, 1, NN_FACE), the union of one-voxel dilations along x, y
/// and z of the same input.
void dilateFaces(openvdb::MaskTree& mask);

/// The same dilation of a float tree's active voxels, in place: voxels activated keep their
/// (inactive) values, and leaves added take the value of the tile they replace, as
/// Tree::topologyUnion with the dilated mask would (a level set's band grown by one voxel,
/// LevelSetTracker::track's NN_FACE step), without copying the tree.
void dilateFaces(openvdb::FloatTree& tree);

} // namespace vdbio
} // namespace ghostfx
