/// @file   MeshFile.h
/// @brief  The liquid surface as a triangle mesh: a level set polygonised by OpenVDB's
///         tools::volumeToMesh, a velocity per vertex for motion blur, written as .ply or .obj.
/// @details The mesh is the zero crossing of the `surface` level set the volume output builds
///          (FrameFiles.h, makeVolumeGrids), so it is the same surface whatever the surface
///          method. tools::volumeToMesh (a dual method) places a vertex in each cell of eight
///          voxel centres the surface crosses and joins the four cells around each crossed voxel
///          edge into a quad; `adaptivity` > 0 merges cells where the surface is flat, so flat
///          parts get fewer, larger polygons. Its quads are split into two triangles along the
///          diagonal from their first corner. The triangles wind counter-clockwise seen from
///          outside the liquid (normals point out, into the air).
///
///          Per vertex: the normal is the area-weighted mean of the normals of the triangles
///          around it (unit length); the velocity is the "vel" grid (the Shepard-normalised
///          SPH velocity of the particles, FrameFiles.h) read trilinearly at the vertex
///          (tools::BoxSampler), so a uniform flow gives every vertex that velocity.
///
///          Files, chosen by the extension of the path:
///          - `.ply`: binary little-endian PLY 1.0, vertex properties float x y z nx ny nz and,
///            where a velocity was sampled, float vx vy vz (m/s, for renderers and tools that
///            read extra vertex properties; readers that do not know them skip them); faces as `list uchar int vertex_indices`. Comment lines carry the
///            file metadata (frame, time, scene).
///          - `.obj`: Wavefront OBJ text, `v` positions, `vn` normals, `f a//a b//b c//c`
///            triangles (1-based); OBJ has no velocity, so none is written.
///          Both are written atomically (AtomicFile.h).
///
///          The volumeToMesh header stays in MeshFile.cc (STACK.md: heavy OpenVDB templates in
///          their own translation unit); this header needs only <openvdb/openvdb.h>.
#pragma once

#include <openvdb/openvdb.h>

#include <cstddef>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// What makeSurfaceMesh builds.
struct MeshOptions
{
    /// tools::volumeToMesh's adaptivity, in [0, 1]: 0 keeps one vertex per surface voxel (a
    /// closed, manifold mesh of a closed surface); larger values merge voxels where the surface
    /// is flat into fewer, larger polygons (tests/vdbio/test_mesh_file.cc measures both).
    double adaptivity = 0;

    /// Throw ValueError "mesh output: adaptivity = <value>: expected in [0, 1]".
    void validate() const;
};

/// A triangle mesh with per-vertex normals and velocities, world positions in metres.
struct SurfaceMesh
{
    std::vector<openvdb::Vec3s> points;     ///< vertex positions (m)
    std::vector<openvdb::Vec3s> normals;    ///< unit outward normal per vertex
    std::vector<openvdb::Vec3s> velocities; ///< per vertex (m/s); empty: none sampled
    std::vector<openvdb::Vec3I> triangles;  ///< vertex indices, counter-clockwise from outside

    /// The volume the triangles enclose (m^3), by the divergence theorem: the sum over the
    /// triangles (a, b, c) of a . (b x c) / 6, in double. Exact for a closed mesh, positive
    /// for outward-facing triangles.
    double enclosedVolume() const;
};

/// The zero crossing of the level set `surface` as triangles, with the velocity of
/// `velocity` (a Vec3SGrid, read trilinearly in world space) at each vertex, or none when it
/// is null. An empty level set gives an empty mesh.
/// @throw ValueError for a bad option or a surface that is not a level set.
SurfaceMesh makeSurfaceMesh(const openvdb::FloatGrid& surface, const openvdb::Vec3SGrid* velocity,
                            const MeshOptions& options);

/// Write `mesh` to `path` atomically, as PLY or OBJ by its extension (".ply", ".obj"; the file
/// comment describes both). `comments` are written as comment lines (one line each).
/// @throw ValueError for another extension or a mesh whose arrays disagree in length; IoError
///        naming the path if the file cannot be written or its folder does not exist.
void writeMeshFile(const std::string& path, const SurfaceMesh& mesh,
                   const std::vector<std::string>& comments = {});

/// Read a PLY file as writeMeshFile writes it (binary little-endian, float x y z, optional
/// nx ny nz and vx vy vz, triangle faces); for reading frames back in tests and tools.
/// @throw IoError naming the path for a missing file or another layout.
SurfaceMesh readPlyMeshFile(const std::string& path);

/// The file metadata of a frame (FrameFiles.h's fileMetadata: frame, time, scene, method) as
/// "key value" comment lines for writeMeshFile.
std::vector<std::string> meshComments(const openvdb::MetaMap& fileMetadata);

} // namespace vdbio
} // namespace ghostfx
