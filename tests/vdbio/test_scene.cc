/// @file   test_scene.cc
/// @brief  Scene files: parsing, strictness (unknown keys with the closest valid key), overrides,
///         level-set loading and every grid error, role-tagged .vdb scenes, keyed motion.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/Scene.h>

#include "common/Expect.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

namespace fs = std::filesystem;
using namespace ghostfx;
using vdbio::Json;

namespace {

/// A fresh folder with `water.vdb` (grid "surface": a sphere level set) and a scene writer.
class SceneTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        mDir = ghostfx::testing::freshTestDir("scene");
        auto sphere = sph::makeSphereLevelSet(sph::Vec3(0.5f, 0.5f, 0.5f), 0.2f, 0.01f);
        sphere->setName("surface");
        writeGrids("water.vdb", {sphere});
    }

    void writeGrids(const std::string& name, openvdb::GridPtrVec grids)
    {
        openvdb::io::File((mDir / name).string()).write(grids);
    }

    /// A valid scene; tests break one thing in it.
    Json baseScene() const
    {
        return Json::parse(R"({
            "ghostfx_scene": 1,
            "settings": { "method": "ghost", "spacing": 0.02, "frame_range": [1, 3] },
            "solids": [ { "name": "tank",
                          "geometry": { "container": { "min": [0, 0, 0], "max": [1, 1, 1] } } } ],
            "liquids": [ { "name": "water", "geometry": { "file": "water.vdb", "grid": "surface" } } ],
            "outputs": { "directory": "out", "preview": { "width": 320, "height": 200 } }
        })");
    }

    std::string write(const Json& scene, const std::string& name = "scene.json") const
    {
        const std::string path = (mDir / name).string();
        std::ofstream(path) << scene.dump(2);
        return path;
    }

    /// The message of the SceneError/GridError/IoError reading `scene` throws.
    std::string errorOf(const Json& scene, const std::vector<std::string>& overrides = {}) const
    {
        try {
            vdbio::readScene(write(scene), overrides);
        } catch (const Error& e) {
            return e.what();
        }
        ADD_FAILURE() << "expected an error for " << scene.dump();
        return "";
    }

    fs::path mDir;
};

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

} // namespace

TEST_F(SceneTest, ReadsAValidScene)
{
    const vdbio::Scene scene = vdbio::readScene(write(baseScene()));
    EXPECT_EQ(scene.method, "ghost");
    EXPECT_DOUBLE_EQ(scene.spacing, 0.02);
    EXPECT_EQ(scene.firstFrame, 1);
    EXPECT_EQ(scene.lastFrame, 3);
    ASSERT_EQ(scene.solids.size(), 1u);
    ASSERT_EQ(scene.liquids.size(), 1u);
    EXPECT_EQ(scene.liquids[0].name, "water");
    // The sphere of radius 0.2 about (0.5, 0.5, 0.5): phi is 0 on it, to a voxel (0.01 m).
    EXPECT_NEAR(scene.liquids[0].shape.phi(sph::Vec3(0.7f, 0.5f, 0.5f)), 0.0, 0.01);
    EXPECT_TRUE(scene.liquids[0].shape.inside(sph::Vec3(0.5f)));
    // Container: inside the tank is free (phi > 0), the walls are solid.
    EXPECT_GT(scene.solids[0].shape.phi(sph::Vec3(0.5f)), 0.0f);
    EXPECT_LT(scene.solids[0].shape.phi(sph::Vec3(-0.01f, 0.5f, 0.5f)), 0.0f);
    EXPECT_EQ(scene.outputs.previewWidth, 320);
    EXPECT_EQ(scene.outputs.previewFile, "preview.$F4.exr");
    ASSERT_TRUE(scene.outputs.previewBackground); // opaque dark grey unless asked otherwise
    EXPECT_TRUE(scene.outputs.previewSolids);
    EXPECT_EQ(scene.outputs.volumeGrids.size(), 3u);
    // The solver-specific keys are left to the caller: the settings object is still open.
    EXPECT_NO_THROW(scene.settings.finish());
}

TEST_F(SceneTest, UnknownKeysNameThePathAndTheClosestKey)
{
    Json s = baseScene();
    s["liquid"] = s["liquids"];
    s.erase("liquids");
    EXPECT_CONTAINS(errorOf(s), "scene.json': liquid: unknown key (did you mean 'liquids'?)");

    s = baseScene();
    s["solids"][0]["velocty"] = {0, 0, 0};
    EXPECT_CONTAINS(errorOf(s), "solids[0].velocty: unknown key (did you mean 'velocity'?)");

    s = baseScene();
    s["outputs"]["volume"] = {{"grids", {"surface", "densty"}}};
    EXPECT_CONTAINS(
        errorOf(s),
        "grid 'densty' is not one of surface, density, vel, temperature (did you mean 'density'?)");

    s = baseScene();
    s["outputs"]["points"] = {{"chanels", {"v"}}};
    EXPECT_CONTAINS(errorOf(s), "outputs.points.chanels: unknown key (did you mean 'channels'?)");

    // Nothing close: the valid keys are listed.
    s = baseScene();
    s["domain"] = {{"zzzzzzzz", 1}};
    EXPECT_CONTAINS(errorOf(s), "domain.zzzzzzzz: unknown key (valid keys here: kill_box)");
}

TEST_F(SceneTest, VolumeSurfaceMethodIsReadByName)
{
    Json s = baseScene();
    EXPECT_EQ(vdbio::readScene(write(s)).outputs.surfaceMethod, vdbio::SurfaceMethod::Spheres);
    s["outputs"]["volume"] = {{"surface_method", "anisotropic"}};
    EXPECT_EQ(vdbio::readScene(write(s)).outputs.surfaceMethod, vdbio::SurfaceMethod::Anisotropic);
    s["outputs"]["volume"] = {{"surface_method", "anisotropc"}};
    EXPECT_CONTAINS(errorOf(s), "outputs.volume.surface_method = \"anisotropc\": expected one of "
                                "'spheres', 'anisotropic' (did you mean 'anisotropic'?)");
}

TEST_F(SceneTest, WrongTypesAndRangesNameTheValue)
{
    Json s = baseScene();
    s["settings"]["spacing"] = "fine";
    EXPECT_CONTAINS(errorOf(s), "settings.spacing = \"fine\": expected a number");
    s["settings"]["spacing"] = -0.01;
    EXPECT_CONTAINS(errorOf(s), "settings.spacing = -0.01: expected a number > 0");
    s = baseScene();
    s["outputs"]["preview"]["background"] = {2, 0, 0};
    EXPECT_CONTAINS(errorOf(s),
                    "outputs.preview.background = [2,0,0]: expected [r, g, b] in 0 to 1");
    s["outputs"]["preview"]["background"] = "transparent";
    EXPECT_FALSE(vdbio::readScene(write(s)).outputs.previewBackground);
    s["outputs"]["preview"]["frame"] = {{"min", {0, 0, 0}}, {"max", {1, 0, 1}}};
    EXPECT_CONTAINS(errorOf(s), "outputs.preview.frame = ");
    s = baseScene();
    s["settings"]["frame_range"] = {5, 2};
    EXPECT_CONTAINS(errorOf(s), "settings.frame_range = [5,2]: expected [first, last]");
    s["settings"]["frame_range"] = {1, 3000000000.0};
    EXPECT_CONTAINS(errorOf(s), "settings.frame_range = [1,3000000000.0]: expected [first, last] "
                                "with 1 <= first <= last <= 9999999");
    s = baseScene();
    s["liquids"][0]["velocity"] = {1, 2};
    EXPECT_CONTAINS(errorOf(s), "liquids[0].velocity = [1,2]: expected an array of 3 numbers");
    s = baseScene();
    s["ghostfx_scene"] = 7;
    EXPECT_CONTAINS(errorOf(s), "ghostfx_scene = 7: this ghostfx reads scene format 1");
    s = baseScene();
    s.erase("ghostfx_scene");
    EXPECT_CONTAINS(errorOf(s), "ghostfx_scene: missing; expected an integer");
}

TEST_F(SceneTest, GridErrorsNameFileGridAndProblem)
{
    Json s = baseScene();
    s["liquids"][0]["geometry"]["file"] = "nope.vdb";
    EXPECT_CONTAINS(errorOf(s), "liquids[0].geometry: file '" + (mDir / "nope.vdb").string()
                                    + "' does not exist");

    s = baseScene();
    s["liquids"][0]["geometry"]["grid"] = "water";
    EXPECT_CONTAINS(errorOf(s), "has no grid 'water' (grids: 'surface')");

    // Fog volume instead of a level set.
    auto fog = sph::makeSphereLevelSet(sph::Vec3(0.5f), 0.2f, 0.01f);
    openvdb::tools::sdfToFogVolume(*fog);
    fog->setName("fog");
    // Vector grid.
    auto vel = openvdb::Vec3SGrid::create();
    vel->setName("vel");
    vel->tree().setValue(openvdb::Coord(0), openvdb::Vec3s(1, 0, 0));
    // Non-uniform voxels.
    auto stretched = sph::makeSphereLevelSet(sph::Vec3(0.5f), 0.2f, 0.01f);
    stretched->setName("stretched");
    stretched->setTransform(openvdb::math::Transform::createLinearTransform(openvdb::math::Mat4d(
        0.01, 0., 0., 0., 0., 0.02, 0., 0., 0., 0., 0.01, 0., 0., 0., 0., 1.)));
    // NaN inside.
    auto nan = sph::makeSphereLevelSet(sph::Vec3(0.5f), 0.2f, 0.01f);
    nan->setName("nan");
    nan->tree().setValue(nan->transform().worldToIndexNodeCentered(openvdb::Vec3d(0.5, 0.7, 0.5)),
                         std::numeric_limits<float>::quiet_NaN());
    // Empty level set.
    auto empty = openvdb::FloatGrid::create(0.03f);
    empty->setGridClass(openvdb::GRID_LEVEL_SET);
    empty->setTransform(openvdb::math::Transform::createLinearTransform(0.01));
    empty->setName("empty");
    writeGrids("bad.vdb", {fog, vel, stretched, nan, empty});

    auto withGrid = [&](const std::string& grid) {
        Json t = baseScene();
        t["liquids"][0]["geometry"] = {{"file", "bad.vdb"}, {"grid", grid}};
        return errorOf(t);
    };
    EXPECT_CONTAINS(withGrid("fog"), "class is 'fog volume', expected 'level set'");
    EXPECT_CONTAINS(withGrid("vel"), "grid 'vel' in '" + (mDir / "bad.vdb").string()
                                         + "' holds vec3s values, expected a float level set");
    EXPECT_CONTAINS(withGrid("stretched"), "stretched");
    EXPECT_CONTAINS(withGrid("stretched"), "uniform");
    EXPECT_CONTAINS(withGrid("nan"),
                    "grid 'nan': value nan at (0.5, 0.7, 0.5) m, expected finite signed distances");
    EXPECT_CONTAINS(withGrid("empty"), "empty");

    // Not a .vdb at all.
    std::ofstream(mDir / "text.vdb") << "hello";
    s = baseScene();
    s["liquids"][0]["geometry"] = {{"file", "text.vdb"}, {"grid", "surface"}};
    EXPECT_CONTAINS(errorOf(s), "is not a readable .vdb file");
}

TEST_F(SceneTest, MethodIsANameTheProgramChecks)
{
    // vdbio reads the method's name; which names exist, and what each medium may hold, is the
    // program's method registry (tests/cli/test_methods.cc). A gas scene reads like any other.
    Json s = baseScene();
    s["settings"]["method"] = "gas";
    s.erase("liquids");
    s.erase("solids");
    s["gas_sources"] = Json::parse(
        R"([{ "geometry": { "sphere": { "center": [0.5, 0.1, 0.5], "radius": 0.05 } } }])");
    EXPECT_EQ(vdbio::readScene(write(s)).method, "gas");
    EXPECT_EQ(vdbio::readScene(write(baseScene())).method, "ghost");
    s = baseScene();
    s["settings"]["method"] = 3;
    EXPECT_CONTAINS(errorOf(s), "settings.method");
    // Not JSON at all: the parser's line and column are kept, with the key it was in.
    std::ofstream(mDir / "broken.json") << "{ \"ghostfx_scene\": 1, ";
    try {
        vdbio::readScene((mDir / "broken.json").string());
        ADD_FAILURE();
    } catch (const SceneError& e) {
        EXPECT_CONTAINS(e.what(), "broken.json': not valid JSON at line 1, column 23: ");
    }
    std::ofstream(mDir / "nan.json") << "{ \"ghostfx_scene\": 1,\n \"settings\": { \"gravity\": "
                                        "[0, NaN, 0] } }";
    try {
        vdbio::readScene((mDir / "nan.json").string());
        ADD_FAILURE();
    } catch (const SceneError& e) {
        EXPECT_CONTAINS(e.what(), "nan.json': not valid JSON at line 2, column 31 (in "
                                  "settings.gravity[1]): ");
        EXPECT_CONTAINS(e.what(), "; NaN and Infinity are not JSON numbers");
    }
    try {
        vdbio::readScene((mDir / "missing.json").string());
        ADD_FAILURE();
    } catch (const IoError& e) {
        EXPECT_CONTAINS(e.what(), "missing.json': cannot open the file");
    }
}

TEST_F(SceneTest, OverridesSetAnyKey)
{
    const std::string path = write(baseScene());
    const vdbio::Scene scene =
        vdbio::readScene(path, {"settings.spacing=0.05", "solids[0].velocity=[1,0,0]",
                                "outputs.preview.grid=surface", "settings.method=basic"});
    EXPECT_DOUBLE_EQ(scene.spacing, 0.05);
    EXPECT_EQ(scene.solids[0].velocity, sph::Vec3d(1, 0, 0));
    EXPECT_EQ(scene.outputs.previewGrid, "surface");
    EXPECT_EQ(scene.method, "basic");

    auto errorFor = [&](const std::string& o) {
        try {
            vdbio::readScene(path, {o});
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_CONTAINS(errorFor("solids[3].velocity=[0,0,0]"),
                    "-D solids[3].velocity: solids has no element [3] (1 elements)");
    // (A misspelt solver setting such as settings.stifness is reported by the solver's reader:
    // tests/cli checks it through `ghostfx run`.)
    EXPECT_CONTAINS(errorFor("nonsense"), "expected path=value");
    // A misspelt key given by -D is caught by the strict reader like one in the file.
    EXPECT_CONTAINS(errorFor("outputs.volume.voxel_sise=0.01"), "did you mean 'voxel_size'?");
}

TEST_F(SceneTest, FingerprintIgnoresOutputsAndFrameRange)
{
    const std::string path = write(baseScene());
    const std::string a = vdbio::readScene(path).simulationFingerprint();
    EXPECT_EQ(
        a, vdbio::readScene(path, {"outputs.directory=elsewhere", "settings.frame_range=[1,100]"})
               .simulationFingerprint());
    EXPECT_NE(a, vdbio::readScene(path, {"settings.stiffness=5000"}).simulationFingerprint());
}

TEST_F(SceneTest, RoleTaggedVdbIsASceneWithDefaults)
{
    auto water = sph::makeSphereLevelSet(sph::Vec3(0.5f), 0.2f, 0.01f);
    water->setName("water");
    water->insertMeta(vdbio::ROLE_METADATA, openvdb::StringMetadata("liquid"));
    auto floor = sph::makeBoxLevelSet(sph::Vec3(0, -0.1f, 0), sph::Vec3(1, 0, 1), 0.02f);
    floor->setName("floor");
    floor->insertMeta(vdbio::ROLE_METADATA, openvdb::StringMetadata("solid"));
    auto untagged = sph::makeSphereLevelSet(sph::Vec3(0.5f), 0.1f, 0.01f);
    untagged->setName("reference");
    writeGrids("roles.vdb", {water, floor, untagged});

    const vdbio::Scene scene =
        vdbio::readScene((mDir / "roles.vdb").string(), {"settings.frame_range=[1,2]"});
    ASSERT_EQ(scene.liquids.size(), 1u);
    ASSERT_EQ(scene.solids.size(), 1u);
    EXPECT_EQ(scene.liquids[0].name, "water");
    EXPECT_EQ(scene.solids[0].name, "floor");
    // Default spacing: twice the finest voxel (0.01 m).
    EXPECT_NEAR(scene.spacing, 0.02, 1e-8); // voxel sizes are stored in single precision
    EXPECT_EQ(scene.lastFrame, 2);

    untagged->insertMeta(vdbio::ROLE_METADATA, openvdb::StringMetadata("lava"));
    writeGrids("badrole.vdb", {untagged});
    try {
        vdbio::readScene((mDir / "badrole.vdb").string());
        ADD_FAILURE();
    } catch (const SceneError& e) {
        EXPECT_CONTAINS(
            e.what(),
            "grid 'reference' has ghostfx_role 'lava': expected solid, liquid, emitter or source");
    }
}

TEST_F(SceneTest, SpacingTooFineForOpenVdbOrForMemoryIsRefusedBeforeSampling)
{
    // Below OpenVDB's smallest usable voxel: a clear error, not "ArithmeticError: Non-zero
    // scale values required" from inside a transform.
    Json s = baseScene();
    s["settings"]["spacing"] = 1e-7;
    EXPECT_CONTAINS(errorOf(s), "settings.spacing = 1e-07: expected at least 4e-05 m");
    // A 10 m sphere of liquid at 2 mm: 5.2e11 particles. Refused from its size alone, before
    // its level set is built, with the estimate and a spacing that would fit.
    s = baseScene();
    s["settings"]["spacing"] = 0.002;
    s.erase("solids");
    s["liquids"][0]["geometry"] =
        Json::parse(R"({ "sphere": { "center": [0, 0, 0], "radius": 10 } })");
    const std::string e = errorOf(s);
    EXPECT_CONTAINS(e, "liquids[0].geometry.sphere: at spacing 0.002 m this shape needs about "
                       "5.23599e+11 particles");
    EXPECT_CONTAINS(e, "expected a spacing of at least");
    // A solid only gets a band of ghosts under its surface: a 10 x 1 x 10 m floor slab at 1 cm
    // holds 1e8 particles' volume (35 GB) but its band 2 spacings deep holds 4.8e6; accepted.
    s = baseScene();
    s["settings"]["spacing"] = 0.01;
    s["solids"][0]["geometry"] =
        Json::parse(R"({ "box": { "min": [-5, -1, -5], "max": [5, 0, 5] } })");
    s["solids"][0]["geometry"]["voxel_size"] = 0.5; // a coarse grid keeps the test fast
    s["liquids"][0]["geometry"] =
        Json::parse(R"({ "box": { "min": [0, 0, 0], "max": [0.1, 0.1, 0.1] } })");
    EXPECT_NO_THROW(vdbio::readScene(write(s)));
}

TEST_F(SceneTest, GasSourceMayBeAFogVolume)
{
    // A fog sphere of radius 0.1 m (density 1 inside, ramping to 0 across the old band).
    auto fog = sph::makeSphereLevelSet(sph::Vec3(0.5f), 0.1f, 0.01f);
    openvdb::tools::sdfToFogVolume(*fog);
    fog->setName("smoke");
    writeGrids("smoke.vdb", {fog});
    Json s = Json::parse(R"({ "ghostfx_scene": 1, "settings": { "method": "gas", "spacing": 0.03 },
        "gas_sources": [ { "geometry": { "file": "smoke.vdb", "grid": "smoke", "threshold": 0.5 } } ] })");
    const vdbio::Scene scene = vdbio::readScene(write(s));
    ASSERT_EQ(scene.gasSources.size(), 1u);
    const sph::LevelSet& region = scene.gasSources[0].shape;
    // sdfToFogVolume ramps the density linearly from 1 at phi = -band (0.03 m) to 0 at the
    // surface, so density 0.5 lies 0.015 m inside: the region's radius is 0.085 m, to a voxel
    // (the mask's staircase and one smoothing pass).
    const float r = 0.085f;
    for (const sph::Vec3& d : {sph::Vec3(1, 0, 0), sph::Vec3(0, -1, 0), sph::Vec3(0, 0, 1)}) {
        const float phi = region.phi(sph::Vec3(0.5f) + d * r);
        std::printf("[measured] fog region phi at the expected surface: %.4f m\n", phi);
        EXPECT_NEAR(phi, 0.0f, 0.01f);
    }
    EXPECT_TRUE(region.inside(sph::Vec3(0.5f)));
    // A threshold above every density leaves nothing: a clear error.
    s["gas_sources"][0]["geometry"]["threshold"] = 2;
    EXPECT_CONTAINS(errorOf(s), "no voxel of the fog volume exceeds the threshold 2");
    // Liquids and solids still need level sets.
    s = baseScene();
    s["liquids"][0]["geometry"] = {{"file", "smoke.vdb"}, {"grid", "smoke"}};
    EXPECT_CONTAINS(errorOf(s), "class is 'fog volume', expected 'level set'");
}

TEST_F(SceneTest, ForceFieldsReadStrictlyAndBelongToTheFingerprint)
{
    // A gas scene with the [RYY15] Fig. 7 attractor.
    Json s = baseScene();
    s.erase("liquids");
    s["settings"]["method"] = "gas";
    s["gas_sources"] = Json::parse(
        R"([{ "geometry": { "sphere": { "center": [0.5, 0.1, 0.5], "radius": 0.05 } } }])");
    s["force_fields"] = Json::parse(R"([
        { "name": "magic", "attractor": { "position": [0.5, 0.8, 0.5], "strength": 3, "radius": 0.2 } },
        { "attractor": { "position": [0, 1, 0], "strength": -1.5, "falloff": "constant" } } ])");
    const vdbio::Scene scene = vdbio::readScene(write(s));
    ASSERT_EQ(scene.forceFields.size(), 2u);
    EXPECT_EQ(scene.forceFields[0].name, "magic");
    EXPECT_EQ(scene.forceFields[0].attractor.position, sph::Vec3d(0.5, 0.8, 0.5));
    EXPECT_DOUBLE_EQ(scene.forceFields[0].attractor.strength, 3.0);
    EXPECT_DOUBLE_EQ(scene.forceFields[0].attractor.radius, 0.2);
    EXPECT_EQ(scene.forceFields[0].attractor.falloff, "inverse_square");
    EXPECT_EQ(scene.forceFields[1].name, "force_fields[1]");         // default name: the path
    EXPECT_DOUBLE_EQ(scene.forceFields[1].attractor.radius, 0.1);    // default radius (m)
    EXPECT_DOUBLE_EQ(scene.forceFields[1].attractor.strength, -1.5); // negative: repels
    EXPECT_EQ(scene.forceFields[1].attractor.falloff, "constant");

    // Bad input: one line naming the key path, the value and what was expected.
    auto bad = [&](const std::string& override) { return errorOf(s, {override}); };
    EXPECT_CONTAINS(bad("force_fields[0].attractor.radius=-0.1"),
                    "scene.json': force_fields[0].attractor.radius = -0.1: expected a number > 0");
    EXPECT_CONTAINS(bad("force_fields[0].attractor.strength=\"big\""),
                    "scene.json': force_fields[0].attractor.strength = \"big\": expected a number");
    EXPECT_CONTAINS(
        bad("force_fields[0].attractor.position=[1,2]"),
        "scene.json': force_fields[0].attractor.position = [1,2]: expected an array of 3 numbers");
    EXPECT_CONTAINS(bad("force_fields[0].attractor.falloff=cubic"),
                    "scene.json': force_fields[0].attractor.falloff = \"cubic\": expected one of "
                    "'inverse_square', 'constant'");
    EXPECT_CONTAINS(
        bad("force_fields[0].attractor.strenght=2"),
        "scene.json': force_fields[0].attractor.strenght: unknown key (did you mean 'strength'?)");
    Json t = s;
    t["force_fields"][0]["attractor"].erase("strength");
    EXPECT_CONTAINS(errorOf(t),
                    "scene.json': force_fields[0].attractor.strength: missing; expected a number");
    t = s;
    t["force_fields"][0]["atractor"] = t["force_fields"][0]["attractor"];
    t["force_fields"][0].erase("attractor");
    EXPECT_CONTAINS(
        errorOf(t),
        "scene.json': force_fields[0].atractor: unknown key (did you mean 'attractor'?)");
    t = s;
    t["force_fields"][0].erase("attractor");
    EXPECT_CONTAINS(errorOf(t),
                    "scene.json': force_fields[0].attractor: missing; expected a field kind: "
                    "'attractor'");
    t = s;
    t["force_field"] = t["force_fields"];
    t.erase("force_fields");
    EXPECT_CONTAINS(errorOf(t),
                    "scene.json': force_field: unknown key (did you mean 'force_fields'?)");

    // Part of the simulation fingerprint: a checkpoint of the scene without the field (or with
    // another strength) is refused for the scene with it.
    const std::string path = write(s, "gas.json");
    Json plain = s;
    plain.erase("force_fields");
    const std::string without =
        vdbio::readScene(write(plain, "plain.json")).simulationFingerprint();
    const std::string with = vdbio::readScene(path).simulationFingerprint();
    EXPECT_NE(without, with);
    EXPECT_NE(
        with,
        vdbio::readScene(path, {"force_fields[0].attractor.strength=4"}).simulationFingerprint());
    EXPECT_EQ(with,
              vdbio::readScene(path, {"outputs.directory=elsewhere"}).simulationFingerprint());
}
