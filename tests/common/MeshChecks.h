/// @file   MeshChecks.h
/// @brief  Test helpers for triangle meshes: edge counts (open, non-manifold, inconsistently
///         wound edges), the volume a level set encloses, and Assimp's reading of a mesh file.
#pragma once

#include <ghostfx/vdbio/MeshFile.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>

namespace ghostfx {
namespace testing {

/// How the edges of a triangle mesh are shared.
struct EdgeCounts
{
    std::size_t edges = 0;       ///< distinct undirected edges
    std::size_t open = 0;        ///< used by one triangle
    std::size_t nonManifold = 0; ///< used by three or more
    /// Used by two triangles that run along it the same way (a closed surface wound
    /// consistently has every edge run once each way).
    std::size_t misoriented = 0;
};

/// The edge counts of `mesh`'s triangles.
inline EdgeCounts countEdges(const vdbio::SurfaceMesh& mesh)
{
    // Per undirected edge (low, high): how many triangles run low -> high and high -> low.
    std::map<std::pair<unsigned, unsigned>, std::pair<int, int>> uses;
    for (const openvdb::Vec3I& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            const unsigned a = t[k], b = t[(k + 1) % 3];
            auto& u = uses[{std::min(a, b), std::max(a, b)}];
            (a < b ? u.first : u.second) += 1;
        }
    }
    EdgeCounts c;
    c.edges = uses.size();
    for (const auto& [edge, u] : uses) {
        const int n = u.first + u.second;
        if (n == 1) ++c.open;
        else if (n > 2) ++c.nonManifold;
        else if (u.first != 1) ++c.misoriented;
    }
    return c;
}

/// The volume (m^3) where the trilinear interpolant of `phi` is negative, from `n`^3 samples
/// per voxel over the active bounding box: the region the mesh's vertices and faces
/// approximate. On the liquid balls of tests/vdbio/test_mesh_file.cc (radius 6.5 h at h / 2
/// voxels) 4^3 and 6^3 samples per voxel agree within 0.05 % (measured).
inline double trilinearVolume(const openvdb::FloatGrid& phi, int n)
{
    const openvdb::CoordBBox box = phi.evalActiveVoxelBoundingBox();
    const openvdb::FloatGrid::ConstAccessor acc = phi.getConstAccessor();
    std::size_t inside = 0;
    const double step = 1.0 / n;
    for (int i = box.min().x() * n; i <= box.max().x() * n; ++i) {
        for (int j = box.min().y() * n; j <= box.max().y() * n; ++j) {
            for (int k = box.min().z() * n; k <= box.max().z() * n; ++k) {
                const openvdb::Vec3d x(i * step, j * step, k * step);
                if (openvdb::tools::BoxSampler::sample(acc, x) < 0) ++inside;
            }
        }
    }
    const double dx = phi.voxelSize()[0] * step;
    return double(inside) * dx * dx * dx;
}

/// What Assimp reads of a mesh file: vertices and faces of its meshes, summed.
struct AssimpCounts
{
    bool read = false;
    std::string error;
    std::size_t vertices = 0, faces = 0;
};

/// Read `path` with Assimp::Importer, joining identical vertices (the OBJ reader makes one
/// vertex per face corner; the ones that share a position and a normal are the file's vertex).
inline AssimpCounts assimpCounts(const std::string& path)
{
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path, aiProcess_JoinIdenticalVertices);
    AssimpCounts c;
    if (!scene) {
        c.error = importer.GetErrorString();
        return c;
    }
    c.read = true;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        c.vertices += scene->mMeshes[m]->mNumVertices;
        c.faces += scene->mMeshes[m]->mNumFaces;
    }
    return c;
}

} // namespace testing
} // namespace ghostfx
