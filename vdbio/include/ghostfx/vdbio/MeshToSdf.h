/// @file   MeshToSdf.h
/// @brief  Triangle meshes (OBJ, PLY, STL, ... through Assimp) to narrow-band level sets.
/// @details The mesh is read with Assimp (triangulated, node transforms applied), its vertices
///          are welded by position, and OpenVDB's tools::meshToLevelSet computes the signed
///          distance to the triangles in a band of `halfWidth` voxels on each side. The sign
///          comes from an inside/outside classification, which is only meaningful for a closed
///          (watertight) mesh: MeshStats counts the open edges so callers can warn.
#pragma once

#include <openvdb/openvdb.h>

#include <cstddef>
#include <string>

namespace ghostfx {
namespace vdbio {

/// Conversion settings; validate() throws ValueError naming the field and the bad value.
struct MeshToSdfOptions
{
    double voxelSize = 0; ///< voxel edge of the level set (m), > 0 (no default)
    double halfWidth = 3; ///< narrow-band half width (voxels), >= 1
    std::string gridName = "surface";
    /// If non-empty, stored as string grid metadata "ghostfx_role": solid, liquid, emitter or
    /// source (the roles a scene .vdb understands, DESIGN.md "Scene files").
    std::string role;
    double scale = 1; ///< uniform scale applied to the mesh (mesh units -> m), > 0
    /// convertMeshFile(): add the grid to an existing .vdb (a role-tagged scene holding a solid
    /// and a liquid) instead of writing a file of that one grid; a file that does not exist yet
    /// is created.
    bool append = false;
    /// With `append`: a grid of the same name already in the file is replaced (in its place);
    /// without it, such a grid is refused.
    bool replace = false;

    void validate() const;
};

/// Facts about the mesh that was converted (after welding vertices by position).
struct MeshStats
{
    std::size_t vertices = 0, triangles = 0;
    /// Edges used by exactly one triangle: non-zero means the mesh is open and the
    /// inside/outside sign of the level set may be wrong.
    std::size_t boundaryEdges = 0;
    /// Edges shared by more than two triangles (also breaks inside/outside).
    std::size_t nonManifoldEdges = 0;
    /// World bounds of the (scaled) mesh (m).
    openvdb::Vec3d boundsMin{0.0}, boundsMax{0.0};
};

/// The allowed values of MeshToSdfOptions::role, comma-separated ("solid, liquid, ...").
std::string meshRoles();

/// Read `meshPath` and convert it to a level set named `options.gridName`.
/// Throws ValueError for bad options, IoError for a missing or unreadable file, GridError for a
/// mesh without triangles or a conversion that yields no voxels.
openvdb::FloatGrid::Ptr meshToLevelSet(const std::string& meshPath, const MeshToSdfOptions& options,
                                       MeshStats* stats = nullptr);

/// meshToLevelSet() then write the grid to `vdbPath` atomically: the file holds that one grid,
/// or, with `options.append`, the grids it already held and this one (the file's metadata
/// kept). Throws ValueError, before converting anything, for an appended grid whose name is in
/// the file already (unless `options.replace`), IoError for an existing file that cannot be
/// read. Returns the grid that was written.
openvdb::FloatGrid::Ptr convertMeshFile(const std::string& meshPath, const std::string& vdbPath,
                                        const MeshToSdfOptions& options,
                                        MeshStats* stats = nullptr);

} // namespace vdbio
} // namespace ghostfx
