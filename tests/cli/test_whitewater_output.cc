/// @file   test_whitewater_output.cc
/// @brief  Whitewater end to end: `ghostfx run` with outputs.whitewater writes a points file
///         (and a fog file) per frame, a resumed run continues it bit for bit, `ghostfx
///         whitewater` over the run's points files makes the same particles, and bad input is
///         refused in one line before anything is written.
#include <ghostfx/vdbio/Readers.h>

#include "CliHarness.h"
#include "common/Expect.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

namespace fs = std::filesystem;
using namespace ghostfx;
using vdbio::Json;

namespace {

using ghostfx::testing::CliTest;
using ghostfx::testing::Result;

/// One whitewater particle as its file holds it, and the file's particles by id.
struct Particle
{
    std::array<double, 3> p, v;
    int type = 0;
    double age = 0;
    bool operator==(const Particle& o) const
    {
        return p == o.p && v == o.v && type == o.type && age == o.age;
    }
};
std::map<std::int64_t, Particle> readWhitewater(const fs::path& file)
{
    const vdbio::PointsData d = vdbio::readPoints(file.string(), "whitewater", "test");
    std::map<std::string, const vdbio::Column*> c;
    for (const vdbio::Column& column : d.columns) c[column.name] = &column;
    std::map<std::int64_t, Particle> out;
    for (std::size_t r = 0; r < d.count; ++r) {
        Particle q;
        for (int k = 0; k < 3; ++k) {
            q.p[std::size_t(k)] = c.at("P")->value(r, k);
            q.v[std::size_t(k)] = c.at("v")->value(r, k);
        }
        q.type = int(c.at("type")->value(r, 0));
        q.age = c.at("age")->value(r, 0);
        out[std::int64_t(c.at("id")->value(r, 0))] = q;
    }
    return out;
}

std::string frameName(const char* stem, int frame)
{
    char name[64];
    std::snprintf(name, sizeof(name), "%s.%04d.vdb", stem, frame);
    return name;
}

/// Each test gets a fresh folder and a small dam break: a 15 x 25 x 12 cm column at 2.5 cm
/// spacing in a 50 x 40 x 12 cm tank, DFSPH; its surge hits the far wall at about 0.3 s
/// (frame 9 at 30 frames per second) and throws spray.
class WhitewaterOutput : public CliTest
{
protected:
    void SetUp() override { mDir = ghostfx::testing::freshTestDir("whitewater_output"); }

    static Json damBreak()
    {
        return Json::parse(R"({
            "ghostfx_scene": 1,
            "settings": { "method": "ghost", "spacing": 0.025, "pressure": "dfsph",
                          "frame_range": [1, 14], "seed": 2 },
            "solids": [ { "name": "tank", "geometry": { "container": {
                "min": [0, 0, 0], "max": [0.5, 0.4, 0.125] } } } ],
            "liquids": [ { "name": "column", "geometry": { "box": {
                "min": [0, 0, 0], "max": [0.15, 0.25, 0.125] } } } ],
            "domain": { "kill_box": { "min": [-0.1, -0.1, -0.1], "max": [0.6, 0.6, 0.3] } },
            "outputs": { "points": { "channels": ["v", "id"] }, "volume": false,
                         "stats": false, "checkpoint": { "every": 7 },
                         "whitewater": { "fog_voxel_size": 0.02 } }
        })");
    }

    void runInto(const std::string& scene, const fs::path& out, const std::string& args = "")
    {
        const Result r =
            run("run " + scene + " --out " + out.string() + " --progress none " + args);
        ASSERT_EQ(r.code, 0) << r.err;
    }
};

} // namespace

// The run writes whitewater per frame: none in the first frame, a little from the surge's front
// (15 particles at frame 5), most where it hits the far wall (110 at frame 9), with the fog
// grids of each class in a file of their own; `ghostfx whitewater` over its points files makes the same
// particles, bit for bit, as does a run resumed from its checkpoint at frame 7.
TEST_F(WhitewaterOutput, InlinePostProcessAndResumeMakeTheSameParticles)
{
    const std::string scene = write(damBreak());
    const fs::path a = mDir / "a", post = mDir / "post", resumed = mDir / "resumed";
    runInto(scene, a);
    std::size_t total = 0;
    for (int f = 1; f <= 14; ++f) {
        ASSERT_TRUE(fs::exists(a / frameName("whitewater", f))) << f;
        ASSERT_TRUE(fs::exists(a / frameName("whitewater_fog", f))) << f;
        total += readWhitewater(a / frameName("whitewater", f)).size();
    }
    std::printf("[measured] dam break whitewater: %zu particles at frame 14, %zu over all frames\n",
                readWhitewater(a / frameName("whitewater", 14)).size(), total);
    EXPECT_EQ(readWhitewater(a / frameName("whitewater", 1)).size(), 0u);
    EXPECT_GT(readWhitewater(a / frameName("whitewater", 9)).size(),
              3 * readWhitewater(a / frameName("whitewater", 5)).size());

    const Result r = run("whitewater " + a.string() + " --out " + post.string() + " -q");
    ASSERT_EQ(r.code, 0) << r.err;
    runInto(scene, resumed, "--resume " + (a / "checkpoint.0007.h5").string());
    for (int f = 1; f <= 14; ++f) {
        const auto inline_ = readWhitewater(a / frameName("whitewater", f));
        EXPECT_TRUE(readWhitewater(post / frameName("whitewater", f)) == inline_) << f;
        if (f > 7)
            EXPECT_TRUE(readWhitewater(resumed / frameName("whitewater", f)) == inline_) << f;
    }
    const vdbio::ActiveVoxels foam =
        vdbio::readActiveVoxels((a / frameName("whitewater_fog", 14)).string(), "foam", "test");
    EXPECT_GT(foam.ijk.size(), 0u);
}

// Bad input is refused in one line naming what is wrong, before anything is written.
TEST_F(WhitewaterOutput, BadInputIsRefusedInOneLine)
{
    Json scene = damBreak();
    scene["settings"]["whitewater"] = {{"energy_min", 6}};
    const fs::path out = mDir / "bad";
    EXPECT_CONTAINS(errorLine("run " + write(scene) + " --out " + out.string()),
                    "whitewater setting energyMax = 5: expected a number above energyMin (6)");
    scene["settings"]["whitewater"] = {{"spray_drag", -1}};
    EXPECT_CONTAINS(errorLine("run " + write(scene) + " --out " + out.string()),
                    "settings.whitewater.spray_drag = -1: expected a number >= 0 (1/s)");
    scene["settings"].erase("whitewater");
    scene["outputs"]["whitewater"] = {{"file", "white.vdb"}};
    EXPECT_CONTAINS(errorLine("run " + write(scene) + " --out " + out.string()),
                    "outputs.whitewater.file = \"white.vdb\": expected a frame pattern with $F");
    EXPECT_FALSE(fs::exists(out / frameName("liquid_points", 1)));
    const Json gas = Json::parse(R"({
        "ghostfx_scene": 1, "settings": { "method": "gas", "spacing": 0.04 },
        "gas_sources": [ { "name": "burner", "temperature": 600,
                           "geometry": { "sphere": { "center": [0, 0.1, 0], "radius": 0.1 } } } ],
        "outputs": { "whitewater": true } })");
    EXPECT_CONTAINS(errorLine("run " + write(gas, "gas.json") + " --out " + out.string()),
                    "outputs.whitewater: whitewater is made from a liquid's splashes in liquid "
                    "scenes; this gas scene makes none");

    // A post-process needs the liquid's velocities and ids in the points files.
    scene = damBreak();
    scene["outputs"]["points"]["channels"] = Json::array({"density"});
    scene["outputs"]["whitewater"] = false;
    runInto(write(scene), out, "--frames 1-2");
    EXPECT_CONTAINS(errorLine("whitewater " + out.string()),
                    "grid 'particles' has no vector attribute 'v': whitewater reads the liquid's "
                    "P, v and id");
    fs::remove(out / frameName("liquid_points", 1));
    EXPECT_CONTAINS(errorLine("whitewater " + out.string() + " --frames 1-2"),
                    "frame 1 ('liquid_points.0001.vdb') is missing in");
}

// A checkpoint fits the scene with or without whitewater: one written without it resumes with
// whitewater starting at its frame, one written with it resumes without (its state dropped).
TEST_F(WhitewaterOutput, ACheckpointResumesWithWhitewaterSwitchedOnOrOff)
{
    Json scene = damBreak();
    scene["settings"]["frame_range"] = Json::array({1, 4});
    scene["outputs"]["checkpoint"]["every"] = 2;
    scene["outputs"]["whitewater"] = false;
    const fs::path plain = mDir / "plain", on = mDir / "on", off = mDir / "off";
    runInto(write(scene, "plain.json"), plain);
    EXPECT_FALSE(fs::exists(plain / frameName("whitewater", 2)));
    scene["outputs"]["whitewater"] = true;
    const std::string withWhitewater = write(scene, "white.json");
    runInto(withWhitewater, on, "--resume " + (plain / "checkpoint.0002.h5").string());
    EXPECT_FALSE(fs::exists(on / frameName("whitewater", 2)));
    EXPECT_TRUE(fs::exists(on / frameName("whitewater", 3)));
    EXPECT_TRUE(fs::exists(on / frameName("whitewater", 4)));
    scene["outputs"]["whitewater"] = false;
    runInto(write(scene, "off.json"), off,
            "--resume " + (on / "checkpoint.0004.h5").string() + " --frames 1-6");
    EXPECT_TRUE(fs::exists(off / frameName("liquid_points", 6)));
    EXPECT_FALSE(fs::exists(off / frameName("whitewater", 5)));
}
