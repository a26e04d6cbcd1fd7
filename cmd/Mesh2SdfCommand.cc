/// @file   Mesh2SdfCommand.cc
/// @brief  `ghostfx mesh2sdf`: convert an OBJ/PLY/STL/... triangle mesh to a level set .vdb.
#include "Command.h"

#include <ghostfx/vdbio/MeshToSdf.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

namespace ghostfx {
namespace cmd {

Command addMesh2SdfCommand(CLI::App& parent)
{
    auto args = std::make_shared<FileToFileArgs<vdbio::MeshToSdfOptions>>();
    vdbio::MeshToSdfOptions& o = args->options;
    CLI::App* c = addFileToFileCommand(parent, "mesh2sdf",
                                       "Convert a closed triangle mesh (OBJ, PLY, STL, ... read "
                                       "with Assimp) to a narrow-band level set .vdb",
                                       "mesh", "input mesh file", "output .vdb file", *args);
    c->add_option("--voxel-size", o.voxelSize, "voxel edge (m, after --scale)")->required();
    c->add_option("--half-width", o.halfWidth, "narrow-band half width (voxels)")
        ->capture_default_str();
    c->add_option("--name", o.gridName, "grid name")->capture_default_str();
    c->add_option("--role", o.role,
                  "scene role stored as grid metadata 'ghostfx_role': " + vdbio::meshRoles());
    c->add_option("--scale", o.scale, "uniform scale from mesh units to m")->capture_default_str();
    CLI::Option* append =
        c->add_flag("--append", o.append,
                    "add the grid to the output .vdb, keeping the grids it holds (a scene of a "
                    "solid and a liquid from two calls); a grid of the same name is refused");
    c->add_flag("--replace", o.replace, "with --append: replace a grid of the same name")
        ->needs(append);
    return {c, [args] {
                const vdbio::MeshToSdfOptions& o = args->options;
                const auto t0 = std::chrono::steady_clock::now();
                vdbio::MeshStats stats;
                const openvdb::FloatGrid::Ptr grid =
                    vdbio::convertMeshFile(args->input, args->output, o, &stats);
                const double seconds =
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
                const openvdb::Vec3d lo = grid->indexToWorld(box.min());
                const openvdb::Vec3d hi = grid->indexToWorld(box.max());
                std::printf("ghostfx mesh2sdf: '%s': %zu vertices, %zu triangles, bounds "
                            "(%g, %g, %g) .. (%g, %g, %g) m\n",
                            args->input.c_str(), stats.vertices, stats.triangles,
                            stats.boundsMin.x(), stats.boundsMin.y(), stats.boundsMin.z(),
                            stats.boundsMax.x(), stats.boundsMax.y(), stats.boundsMax.z());
                std::printf("  level set '%s'%s%s: voxel %g m, half width %g voxels, %llu active "
                            "voxels, voxel centres (%g, %g, %g) .. (%g, %g, %g) m\n",
                            o.gridName.c_str(), o.role.empty() ? "" : ", role ", o.role.c_str(),
                            o.voxelSize, o.halfWidth,
                            static_cast<unsigned long long>(grid->activeVoxelCount()), lo.x(),
                            lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
                std::printf("  -> '%s'%s in %.2f s\n", args->output.c_str(),
                            o.append ? " (appended)" : "", seconds);
                if (stats.boundaryEdges > 0 || stats.nonManifoldEdges > 0) {
                    std::fprintf(stderr,
                                 "ghostfx mesh2sdf: warning: the mesh is not closed (%zu open "
                                 "edges, %zu edges shared by more than two triangles): inside "
                                 "and outside of the level set may be wrong\n",
                                 stats.boundaryEdges, stats.nonManifoldEdges);
                }
                return 0;
            }};
}

} // namespace cmd
} // namespace ghostfx
