/// @file   WhitewaterFile.h
/// @brief  Whitewater particles (spray, foam, bubbles) as an OpenVDB PointDataGrid
///         "whitewater" plus one fog grid per class ("spray", "foam", "bubbles"), written
///         atomically to one .vdb file.
/// @details The particles come as plain arrays (WhitewaterPoints), so this library needs no
///          knowledge of the generator that made them (a solver's whitewater model hands its
///          arrays over). Class values: 0 spray, 1 foam, 2 bubble ([IAGT12] Ihmsen, Akinci,
///          Gissler and Teschner 2012, "Unified spray, foam and bubbles for particle-based
///          fluids").
///
///          Fog density: each particle carries the volume of a sphere of radius pscale,
///          V_p = 4/3 pi pscale^3, and splats it trilinearly onto the 8 voxel centres
///          (i, j, k) * dx around its position x:
///            f(i,j,k) = sum_p V_p w_x w_y w_z / dx^3,   w_d = 1 - |x_d / dx - i_d|,
///          the whitewater's volume fraction, clamped to [0, 1]. The weights of a particle sum
///          to one, so while no voxel clamps the fog holds the particles' volume exactly:
///          sum f dx^3 = N V_p. The splat suits voxels about the particle diameter or larger;
///          on finer voxels a particle's volume still lands on its 8 nearest centres and
///          clamps sooner. Only voxels a particle contributes to are active; the background
///          is 0 and the grid class is fog volume. The contributions are summed in double
///          after sorting them by voxel and value, so the same particles in any order give
///          bit-identical grids.
///
///          A file holding a point grid is refused by Blender and pyopenvdb 10 (README.md); write
///          only the fog grids (fogVoxelSize > 0 and the points grid dropped from the list)
///          for those tools.
#pragma once

#include <ghostfx/sph/Types.h>

#include <openvdb/openvdb.h>

#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// Whitewater particles (spray, foam, bubbles) as plain arrays, all of equal length.
struct WhitewaterPoints
{
    std::vector<sph::Vec3> positions;  ///< world position (m)
    std::vector<sph::Vec3> velocities; ///< m/s
    std::vector<std::int64_t> ids;     ///< unique per particle, to match particles across frames
    std::vector<std::int32_t> types;   ///< 0 spray, 1 foam, 2 bubble
    std::vector<float> ages;           ///< time since birth (s)
};

/// Names of the fog grids by class value: "spray", "foam", "bubbles".
constexpr const char* WHITEWATER_FOG_NAMES[] = {"spray", "foam", "bubbles"};

/// What makeWhitewaterGrids builds.
struct WhitewaterGridOptions
{
    /// Particle radius (m), written as the uniform "pscale" attribute and the radius of the
    /// sphere each particle adds to the fog; required > 0.
    double pscale = 0;
    /// PointDataGrid voxel size (m); 0 = automatic (autoPointsVoxelSize in FrameFiles.h). It
    /// only sets how points are bucketed, not their positions.
    double pointsVoxelSize = 0;
    /// Voxel size (m) of the fog grids "spray", "foam", "bubbles"; 0 = no fog grids.
    double fogVoxelSize = 0;

    /// Throw ValueError naming the first bad field and its value.
    void validate() const;
};

/// The PointDataGrid "whitewater" and, when options.fogVoxelSize > 0, the FloatGrids "spray",
/// "foam", "bubbles" (fog volumes, in that order).
/// @details Point attributes: "P" (world position, vec3f offset from the voxel centre, no
///          compression, as makePointsGrid), "v" (vec3f, m/s), "id" (int64), "type" (int32),
///          "age" (float, s), "pscale" (float, m, one uniform value). Points come in OpenVDB's
///          voxel order, not the arrays' order: match them by "id". No particles give a points
///          grid without leaves (as makePointsGrid) and empty fog grids.
/// @throw ValueError for a bad option, arrays of different lengths, a type outside 0..2 or a
///        non-finite position.
openvdb::GridPtrVec makeWhitewaterGrids(const WhitewaterPoints& points,
                                        const WhitewaterGridOptions& options);

/// The fog grid named `name` of the particles of class `type` (all classes when type < 0),
/// defined in the file's @details; used by makeWhitewaterGrids and by previews.
/// @param voxelSize  voxel edge dx (m), > 0
/// @param pscale     particle radius (m), > 0
/// @throw ValueError for a bad voxel size, pscale or type (> 2), or bad points as above.
openvdb::FloatGrid::Ptr makeWhitewaterFog(const WhitewaterPoints& points, int type,
                                          double voxelSize, double pscale, const std::string& name);

/// Write `grids` (made by makeWhitewaterGrids) with `fileMetadata` (frame, time, scene...) to
/// the .vdb `path` atomically: a temporary file in the same folder, then a rename.
/// @throw IoError if the folder is missing or the file cannot be written.
void writeWhitewaterFile(const std::string& path, const openvdb::GridPtrVec& grids,
                         const openvdb::MetaMap& fileMetadata = openvdb::MetaMap());

} // namespace vdbio
} // namespace ghostfx
