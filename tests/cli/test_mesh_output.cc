/// @file   test_mesh_output.cc
/// @brief  `outputs.mesh` end to end: `ghostfx run` writes one mesh file per frame, of the same
///         surface as the volume file's whether or not that file is written, and refuses bad
///         mesh settings before the first step with one line naming the key.
#include <ghostfx/vdbio/MeshFile.h>

#include "CliHarness.h"
#include "common/Expect.h"
#include "common/MeshChecks.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using namespace ghostfx;
using vdbio::Json;

namespace {

using ghostfx::testing::CliTest;
using ghostfx::testing::Result;
using ghostfx::testing::slurp;

/// Each test gets a fresh folder and a falling ball of water of radius 0.06 m at 0.01 m spacing
/// (about 900 particles, CFL steps), its liquid surface meshed to PLY.
class MeshOutput : public CliTest
{
protected:
    void SetUp() override { mDir = ghostfx::testing::freshTestDir("mesh_output"); }

    static Json ballScene()
    {
        return Json::parse(R"({
            "ghostfx_scene": 1,
            "settings": { "method": "ghost", "spacing": 0.01, "frame_range": [1, 2], "stiffness": 2000,
                          "seed": 3 },
            "liquids": [ { "name": "ball",
                           "geometry": { "sphere": { "center": [0, 0.5, 0], "radius": 0.06 } } } ],
            "outputs": { "points": false, "checkpoint": false, "stats": false,
                         "mesh": { "file": "liquid.$F4.ply" } }
        })");
    }

    /// Run `scene` into `out` with the extra arguments `args`; the run's log.
    std::string runInto(const std::string& scene, const fs::path& out,
                        const std::string& args = "") const
    {
        const Result r = run("run " + scene + " --out " + out.string() + " --progress log " + args);
        EXPECT_EQ(r.code, 0) << r.err;
        return r.err;
    }
};

/// The name of frame `frame` of "liquid.$F4<ext>".
std::string frameName(int frame, const char* ext)
{
    char name[64];
    std::snprintf(name, sizeof(name), "liquid.%04d%s", frame, ext);
    return name;
}

} // namespace

TEST_F(MeshOutput, RunWritesOneClosedMeshPerFrameOfTheVolumeSurface)
{
    const fs::path out = mDir / "out";
    const std::string log = runInto(write(ballScene()), out, "--frames 1-3");
    for (int f = 1; f <= 3; ++f) {
        EXPECT_TRUE(fs::exists(out / frameName(f, ".ply"))) << f;
        EXPECT_CONTAINS(log, "mesh of frame " + std::to_string(f) + " '"
                                 + (out / frameName(f, ".ply")).string() + "': ");
    }
    EXPECT_FALSE(fs::exists(out / frameName(4, ".ply")));

    // Frame 3's mesh against the volume file's surface: the volume it encloses (the issue's
    // 1 %; the level-set sphere of tests/vdbio/test_mesh_file.cc measures -0.3 % at 20 voxels
    // per radius, this ball has 13), closed and consistently wound, read by Assimp alike.
    const std::string ply = (out / frameName(3, ".ply")).string();
    const vdbio::SurfaceMesh mesh = vdbio::readPlyMeshFile(ply);
    openvdb::io::File volume((out / frameName(3, ".vdb")).string());
    volume.open();
    const auto phi = openvdb::gridPtrCast<openvdb::FloatGrid>(volume.readGrid("surface"));
    volume.close();
    ASSERT_TRUE(phi);
    const double voxels = ghostfx::testing::trilinearVolume(*phi, 4);
    std::printf("[measured] frame 3: %zu vertices, %zu triangles, mesh volume %.4e m^3, the "
                "surface's voxels %.4e m^3 (%+.3f %%)\n",
                mesh.points.size(), mesh.triangles.size(), mesh.enclosedVolume(), voxels,
                100 * (mesh.enclosedVolume() / voxels - 1));
    EXPECT_NEAR(mesh.enclosedVolume() / voxels, 1.0, 0.01);
    const ghostfx::testing::EdgeCounts edges = ghostfx::testing::countEdges(mesh);
    EXPECT_EQ(edges.open + edges.nonManifold + edges.misoriented, 0u);
    const ghostfx::testing::AssimpCounts read = ghostfx::testing::assimpCounts(ply);
    ASSERT_TRUE(read.read) << read.error;
    EXPECT_EQ(read.vertices, mesh.points.size());
    EXPECT_EQ(read.faces, mesh.triangles.size());

    // The ball falls freely from rest: after 3 frames (0.1 s) at about g t = 0.98 m/s. The mesh
    // velocities are the liquid's: pressure waves in the ball spread them (measured: -1.00 to
    // -0.95 m/s, the mean -0.977 m/s); the mean within 5 % of g t.
    double vy = 0;
    for (const openvdb::Vec3s& v : mesh.velocities) vy += v.y();
    vy /= double(mesh.velocities.size());
    std::printf("[measured] mean vertex velocity y %.4f m/s (free fall: %.4f)\n", vy, -9.81 * 0.1);
    EXPECT_NEAR(vy, -9.81 * 0.1, 0.05 * 9.81 * 0.1);
}

TEST_F(MeshOutput, MeshIsTheSameWithoutTheVolumeFileForEitherSurfaceMethod)
{
    // The mesh is made of the volume output's surface and velocity whether or not the volume
    // file is written, or holds them: the same file, byte for byte.
    const std::string scene = write(ballScene());
    for (const char* method : {"spheres", "anisotropic"}) {
        const std::string use = std::string(" -D outputs.volume.surface_method=") + method;
        const fs::path a = mDir / (std::string(method) + "_volume");
        const fs::path b = mDir / (std::string(method) + "_no_volume");
        const fs::path c = mDir / (std::string(method) + "_density_only");
        runInto(scene, a, use);
        runInto(scene, b,
                std::string(" -D outputs.volume=false -D outputs.mesh.surface_method=") + method);
        runInto(scene, c, use + " -D 'outputs.volume.grids=[\"density\"]'");
        EXPECT_FALSE(fs::exists(b / frameName(2, ".vdb")));
        for (int f = 1; f <= 2; ++f) {
            const std::string name = frameName(f, ".ply");
            const std::string bytes = slurp(a / name);
            ASSERT_GT(bytes.size(), 1000u) << method << " " << name;
            EXPECT_TRUE(slurp(b / name) == bytes) << method << " " << name << ": no volume file";
            EXPECT_TRUE(slurp(c / name) == bytes) << method << " " << name << ": density only";
        }
    }

    // OBJ by the pattern's extension, with the PLY's vertices and triangles.
    const fs::path obj = mDir / "obj";
    runInto(scene, obj, "--frames 1-1 -D 'outputs.mesh.file=liquid.$F4.obj'");
    const ghostfx::testing::AssimpCounts read =
        ghostfx::testing::assimpCounts((obj / frameName(1, ".obj")).string());
    ASSERT_TRUE(read.read) << read.error;
    const vdbio::SurfaceMesh ply =
        vdbio::readPlyMeshFile((mDir / "spheres_volume" / frameName(1, ".ply")).string());
    EXPECT_EQ(read.vertices, ply.points.size());
    EXPECT_EQ(read.faces, ply.triangles.size());
}

TEST_F(MeshOutput, BadMeshSettingsAreRefusedBeforeTheFirstStep)
{
    const fs::path out = mDir / "out";
    const std::string scene = write(ballScene());
    auto refused = [&](const std::string& define) {
        return errorLine("run " + scene + " --out " + out.string() + " -D '" + define + "'");
    };
    EXPECT_CONTAINS(refused("outputs.mesh.file=liquid.$F4.stl"),
                    "outputs.mesh.file = \"liquid.$F4.stl\": this output is written as a PLY or "
                    "OBJ triangle mesh: "
                    "expected a name ending in .ply or .obj, not .stl");
    EXPECT_CONTAINS(refused("outputs.mesh.file=liquid.ply"),
                    "outputs.mesh.file = \"liquid.ply\": expected a frame pattern with $F");
    EXPECT_CONTAINS(refused("outputs.mesh.adaptivity=1.5"), "outputs.mesh.adaptivity");
    EXPECT_CONTAINS(refused("outputs.mesh.file=meshes/liquid.$F4.ply"),
                    "outputs.mesh.file = 'meshes/liquid.$F4.ply': folder '"
                        + (out / "meshes").string() + "' does not exist");
    // Where the volume file is written, the mesh is its surface.
    EXPECT_CONTAINS(refused("outputs.mesh.surface_method=anisotropic"),
                    "outputs.mesh.surface_method = \"anisotropic\": expected "
                    "outputs.volume.surface_method (\"spheres\"): the mesh is the volume's "
                    "surface");
    // Nothing simulated, nothing written.
    EXPECT_FALSE(fs::exists(out / frameName(1, ".vdb")));

    // A gas scene has no liquid surface to mesh.
    const Json gas = Json::parse(R"({
        "ghostfx_scene": 1,
        "settings": { "method": "gas", "spacing": 0.04, "frame_range": [1, 1] },
        "domain": { "kill_box": { "min": [-0.5, -0.1, -0.5], "max": [0.5, 1.5, 0.5] } },
        "gas_sources": [ { "name": "burner", "geometry": { "sphere": { "center": [0, 0.1, 0], "radius": 0.1 } },
                           "temperature": 600 } ],
        "outputs": { "mesh": true }
    })");
    const fs::path gasOut = mDir / "gas";
    EXPECT_CONTAINS(errorLine("run " + write(gas, "gas.json") + " --out " + gasOut.string()),
                    "outputs.mesh: a mesh is made of the liquid's surface, and this gas scene "
                    "has no liquid");
    EXPECT_FALSE(fs::exists(gasOut));
}
