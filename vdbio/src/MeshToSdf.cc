/// @file   MeshToSdf.cc
/// @brief  Assimp mesh reading, vertex welding, edge checks and tools::meshToLevelSet.
#include <ghostfx/vdbio/MeshToSdf.h>

#include "FrameGridsDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <openvdb/io/File.h>
#include <openvdb/tools/MeshToVolume.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <unordered_map>
#include <vector>

namespace ghostfx {
namespace vdbio {

namespace fs = std::filesystem;

namespace {

const char* const ROLES[] = {"solid", "liquid", "emitter", "source"};

// A level set this many voxels across on one axis is refused as a probable unit mistake
// (a mesh in mm converted with a voxel size in m): its narrow band alone would be gigabytes.
constexpr double MAX_VOXELS_ACROSS = 100000.0;

struct TriangleMesh
{
    std::vector<openvdb::Vec3s> points; ///< world positions (m), welded
    std::vector<openvdb::Vec3I> triangles;
};

/// Key of a vertex position for welding: the bit patterns of its coordinates (exact match;
/// +0 and -0 are made equal first).
struct PositionHash
{
    std::size_t operator()(const std::array<std::uint32_t, 3>& key) const
    {
        std::uint64_t h = 1469598103934665603ull; // FNV-1a over the three words
        for (std::uint32_t word : key) h = (h ^ word) * 1099511628211ull;
        return std::size_t(h);
    }
};

std::array<std::uint32_t, 3> positionKey(const openvdb::Vec3s& p)
{
    std::array<std::uint32_t, 3> key;
    for (int i = 0; i < 3; ++i) {
        const float c = p[i] + 0.0f; // -0 -> +0
        std::memcpy(&key[std::size_t(i)], &c, sizeof(float));
    }
    return key;
}

/// Read every triangle of every mesh in the file, scaled, with vertices welded by position.
/// Assimp's own JoinIdenticalVertices keeps vertices apart when their normals or texture
/// coordinates differ (face-normal OBJ, STL), which would make every edge look open.
TriangleMesh readTriangles(const std::string& meshPath, double scale)
{
    std::error_code ec;
    if (!fs::exists(meshPath, ec)) throw IoError(msg("mesh file '", meshPath, "': no such file"));
    if (!fs::is_regular_file(meshPath, ec)) {
        throw IoError(msg("mesh file '", meshPath, "': not a regular file"));
    }
    Assimp::Importer importer;
    // Points and lines are kept (dropping them all makes Assimp fail with "No meshes
    // remaining") and skipped below: only triangles bound a volume.
    const aiScene* scene =
        importer.ReadFile(meshPath, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices
                                        | aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (!scene) {
        throw IoError(msg("mesh file '", meshPath, "': cannot read it as a mesh (",
                          importer.GetErrorString(), ")"));
    }

    TriangleMesh mesh;
    std::unordered_map<std::array<std::uint32_t, 3>, unsigned, PositionHash> welded;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* part = scene->mMeshes[m];
        std::vector<unsigned> index(part->mNumVertices);
        for (unsigned v = 0; v < part->mNumVertices; ++v) {
            const aiVector3D& p = part->mVertices[v];
            const openvdb::Vec3s x(float(scale * p.x), float(scale * p.y), float(scale * p.z));
            if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2])) {
                throw GridError(msg("mesh file '", meshPath, "': vertex ", v, " of mesh ", m,
                                    " is not finite"));
            }
            const auto inserted = welded.emplace(positionKey(x), unsigned(mesh.points.size()));
            if (inserted.second) mesh.points.push_back(x);
            index[v] = inserted.first->second;
        }
        for (unsigned f = 0; f < part->mNumFaces; ++f) {
            const aiFace& face = part->mFaces[f];
            if (face.mNumIndices != 3) continue;
            const openvdb::Vec3I t(index[face.mIndices[0]], index[face.mIndices[1]],
                                   index[face.mIndices[2]]);
            // Triangles that weld to a line or a point bound nothing.
            if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) continue;
            mesh.triangles.push_back(t);
        }
    }
    return mesh;
}

/// Count edges used by one triangle (open) and by more than two (non-manifold).
void countEdges(const TriangleMesh& mesh, MeshStats& stats)
{
    std::unordered_map<std::uint64_t, unsigned> uses;
    uses.reserve(3 * mesh.triangles.size());
    for (const openvdb::Vec3I& t : mesh.triangles) {
        for (int e = 0; e < 3; ++e) {
            const std::uint64_t a = t[e], b = t[(e + 1) % 3];
            ++uses[a < b ? (a << 32 | b) : (b << 32 | a)];
        }
    }
    for (const auto& edge : uses) {
        if (edge.second == 1) ++stats.boundaryEdges;
        else if (edge.second > 2) ++stats.nonManifoldEdges;
    }
}

void checkOutputFolder(const std::string& vdbPath)
{
    const fs::path folder = fs::path(vdbPath).parent_path();
    std::error_code ec;
    if (!folder.empty() && !fs::is_directory(folder, ec)) {
        throw IoError(msg("'", vdbPath, "': folder '", folder.string(), "' does not exist"));
    }
    if (fs::is_directory(vdbPath, ec)) {
        throw IoError(msg("'", vdbPath, "' is a folder, expected a .vdb file"));
    }
}

/// What an appended grid joins: the grids of the .vdb `vdbPath` (none when it does not exist)
/// and its file metadata; `replaced` is the index of the grid named `options.gridName` that
/// `options.replace` replaces (-1 for none). Such a grid without `replace` is refused.
openvdb::GridPtrVec gridsToKeep(const std::string& vdbPath, const MeshToSdfOptions& options,
                                openvdb::MetaMap& fileMeta, int& replaced)
{
    replaced = -1;
    std::error_code ec;
    if (!fs::exists(vdbPath, ec)) return {};
    openvdb::io::File file(vdbPath);
    openvdb::GridPtrVecPtr grids;
    try {
        file.open(/*delayLoad=*/false);
        grids = file.getGrids();
        fileMeta = *file.getMetadata();
        file.close();
    } catch (const openvdb::Exception& e) {
        throw IoError(msg("mesh2sdf --append: '", vdbPath, "' is not a readable .vdb file (",
                          e.what(), ")"));
    }
    for (std::size_t k = 0; k < grids->size(); ++k) {
        if ((*grids)[k]->getName() != options.gridName) continue;
        if (!options.replace) {
            throw ValueError(msg("mesh2sdf --append: '", vdbPath, "' already has a grid '",
                                 options.gridName,
                                 "': expected a new name (--name) or --replace to overwrite it"));
        }
        replaced = int(k);
    }
    return *grids;
}

} // namespace

std::string meshRoles()
{
    std::string roles;
    for (const char* role : ROLES) roles += (roles.empty() ? "" : ", ") + std::string(role);
    return roles;
}

void MeshToSdfOptions::validate() const
{
    if (!(voxelSize > 0.0) || !std::isfinite(voxelSize)) {
        throw ValueError(msg("voxelSize = ", voxelSize, ": expected a voxel size > 0 (m)"));
    }
    if (!(halfWidth >= 1.0) || !std::isfinite(halfWidth)) {
        throw ValueError(msg("halfWidth = ", halfWidth, ": expected >= 1 (voxels)"));
    }
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        throw ValueError(msg("scale = ", scale, ": expected > 0"));
    }
    if (gridName.empty()) throw ValueError("gridName is empty: expected a grid name");
    if (replace && !append) {
        throw ValueError("replace without append: --replace replaces a grid of the file "
                         "--append adds to");
    }
    const auto isRole = [&](const char* r) { return role == r; };
    if (!role.empty() && std::none_of(std::begin(ROLES), std::end(ROLES), isRole)) {
        throw ValueError(msg("role = '", role, "': expected one of ", meshRoles(), " (or none)"));
    }
}

openvdb::FloatGrid::Ptr meshToLevelSet(const std::string& meshPath, const MeshToSdfOptions& options,
                                       MeshStats* stats)
{
    options.validate();
    const TriangleMesh mesh = readTriangles(meshPath, options.scale);
    if (mesh.triangles.empty()) {
        throw GridError(msg("mesh file '", meshPath, "' contains no triangles"));
    }

    MeshStats local;
    local.vertices = mesh.points.size();
    local.triangles = mesh.triangles.size();
    countEdges(mesh, local);
    openvdb::Vec3d lo(mesh.points[0]), hi(mesh.points[0]);
    for (const openvdb::Vec3s& p : mesh.points) {
        lo = openvdb::math::minComponent(lo, openvdb::Vec3d(p));
        hi = openvdb::math::maxComponent(hi, openvdb::Vec3d(p));
    }
    local.boundsMin = lo;
    local.boundsMax = hi;
    if (stats) *stats = local;

    const double across = (hi - lo).length() / options.voxelSize;
    if (across > MAX_VOXELS_ACROSS) {
        throw ValueError(msg("voxelSize = ", options.voxelSize, ": the mesh '", meshPath, "' is ",
                             (hi - lo).length(), " m across, ", across,
                             " voxels; expected at most ", MAX_VOXELS_ACROSS,
                             " (check --scale and the mesh units)"));
    }

    const openvdb::math::Transform::Ptr xform =
        openvdb::math::Transform::createLinearTransform(options.voxelSize);
    openvdb::FloatGrid::Ptr grid;
    try {
        grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(
            *xform, mesh.points, mesh.triangles, float(options.halfWidth));
    } catch (const openvdb::Exception& e) {
        throw GridError(msg("mesh file '", meshPath, "': conversion failed (", e.what(), ")"));
    }
    if (!grid || grid->activeVoxelCount() == 0) {
        throw GridError(msg("mesh file '", meshPath, "': the level set has no active voxels"));
    }
    grid->setName(options.gridName);
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    if (!options.role.empty()) {
        grid->insertMeta("ghostfx_role", openvdb::StringMetadata(options.role));
    }
    grid->insertMeta("ghostfx_source_mesh",
                     openvdb::StringMetadata(fs::path(meshPath).filename().string()));
    return grid;
}

openvdb::FloatGrid::Ptr convertMeshFile(const std::string& meshPath, const std::string& vdbPath,
                                        const MeshToSdfOptions& options, MeshStats* stats)
{
    options.validate();
    checkOutputFolder(vdbPath);
    openvdb::MetaMap fileMeta;
    int replaced = -1;
    const openvdb::GridPtrVec kept =
        options.append ? gridsToKeep(vdbPath, options, fileMeta, replaced) : openvdb::GridPtrVec{};
    openvdb::FloatGrid::Ptr grid = meshToLevelSet(meshPath, options, stats);
    openvdb::GridCPtrVec grids(kept.begin(), kept.end());
    if (replaced >= 0) grids[std::size_t(replaced)] = grid;
    else grids.push_back(grid);
    fileMeta.insertMeta("creator", openvdb::StringMetadata("ghostfx mesh2sdf"));
    detail::writeVdbFile(vdbPath, "level set", grids, fileMeta);
    return grid;
}

} // namespace vdbio
} // namespace ghostfx
