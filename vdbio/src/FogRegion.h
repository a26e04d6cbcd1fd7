/// @file   FogRegion.h
/// @brief  Private to vdbio: the region of a fog volume as a level set.
#pragma once

#include <ghostfx/sph/LevelSet.h>

#include <openvdb/openvdb.h>

#include <string>

namespace ghostfx {
namespace vdbio {

/// The region where `fog` exceeds `threshold`, as a narrow-band level set (3 voxels, the fog's
/// transform). Throws GridError if the region is empty.
sph::LevelSet fogRegionToLevelSet(const openvdb::FloatGrid& fog, float threshold,
                                  const std::string& name);

} // namespace vdbio
} // namespace ghostfx
