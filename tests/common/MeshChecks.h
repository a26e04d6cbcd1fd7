/// @file   MeshChecks.h
/// @brief  Test helpers for triangle meshes: edge counts (open, non-manifold, inconsistently
///         wound edges), and Assimp's reading of a mesh file.
#pragma once

#include <ghostfx/vdbio/MeshFile.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

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
