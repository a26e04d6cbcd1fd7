/// @file   Info.h
/// @brief  Human-readable description of a .vdb or .h5 file, for `ghostfx info`.
/// @details .vdb: the file's metadata, then per grid its name, value type, class, voxel size,
///          active voxel count, world bounding box, memory and metadata (such as "ghostfx_role");
///          point grids add the point count, attribute names, types and bytes per point, and
///          per attribute the minimum, maximum and mean of each component, taken from the
///          columns vdbio::readPointsGrid returns (P in world space), so they match what the
///          Python reader ghostfx.read_points gives.
///          .h5 / .hdf5: a generic walk of the HDF5 file listing groups, datasets (shape and
///          element type) and attributes with their values, so checkpoints and statistics files
///          are described without knowing their schema.
#pragma once

#include <string>

namespace ghostfx {
namespace vdbio {

/// Multi-line description of `path`, chosen by its extension (.vdb, .h5, .hdf5).
/// Throws IoError naming the file if it is missing, unreadable or of another kind.
std::string describeFile(const std::string& path);

} // namespace vdbio
} // namespace ghostfx
