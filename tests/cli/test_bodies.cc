/// @file   test_bodies.cc
/// @brief  Dynamic solids through `ghostfx run`: the `dynamic` scene key and its errors,
///         bodies.csv and the statistics' `/bodies` group, a resumed run continuing them (its
///         rows kept bit for bit, the solver's new ones within 1e-4), and outputs.volume.solids
///         writing each body's level set where it is.
#include "CliHarness.h"

#include <ghostfx/vdbio/BodyTable.h>

#include <openvdb/tools/LevelSetMeasure.h>

#include <openvdb/tools/LevelSetUtil.h>

#include <cmath>
#include <functional>

namespace fs = std::filesystem;
using ghostfx::vdbio::BodyRow;
using ghostfx::vdbio::Json;

namespace {

using namespace ghostfx::testing;

class Bodies : public CliTest
{
protected:
    static openvdb::FloatGrid::Ptr readGrid(const fs::path& file, const std::string& name)
    {
        openvdb::io::File f(file.string());
        f.open();
        openvdb::FloatGrid::Ptr grid;
        if (f.hasGrid(name)) grid = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid(name));
        f.close();
        return grid;
    }

    void SetUp() override { mDir = freshTestDir("bodies"); }

    /// A 10 x 6 x 10 cm crate of density 500 kg/m^3 held 2 cm above 12 cm of water in a
    /// 30 cm tank, spacing 2 cm, 10 substeps a frame at 30 fps.
    static Json crateScene(int frames)
    {
        Json scene = Json::parse(R"({
            "ghostfx_scene": 1,
            "settings": { "method": "ghost", "spacing": 0.02, "substeps": 10, "seed": 3 },
            "solids": [ { "name": "tank",
                          "geometry": { "container": { "min": [0, 0, 0], "max": [0.3, 0.4, 0.3] } } },
                        { "name": "crate", "dynamic": { "density": 500 },
                          "geometry": { "box": { "min": [0.1, 0.14, 0.1], "max": [0.2, 0.2, 0.2] } } } ],
            "liquids": [ { "name": "water",
                           "geometry": { "box": { "min": [0, 0, 0], "max": [0.3, 0.12, 0.3] } } } ],
            "outputs": { "points": false, "volume": false, "checkpoint": { "every": 0 } }
        })");
        scene["settings"]["frame_range"] = {1, frames};
        return scene;
    }
};

} // namespace

TEST_F(Bodies, CsvHasARowPerBodyPerFrameAndTheStatisticsTheSame)
{
    const std::string path = write(crateScene(8));
    const Result r = run("run " + path + " --out " + (mDir / "out").string() + " -q");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string text = slurp(mDir / "out" / "bodies.csv");
    EXPECT_EQ(text.substr(0, text.find('\n')),
              "frame,time,name,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz");
    const std::vector<BodyRow> rows =
        ghostfx::vdbio::readBodiesCsv((mDir / "out" / "bodies.csv").string());
    ASSERT_EQ(rows.size(), 8u) << "8 frames x 1 body";
    for (std::size_t f = 0; f < rows.size(); ++f) {
        const BodyRow& row = rows[f];
        EXPECT_EQ(row.frame, int(f) + 1);
        EXPECT_EQ(row.name, "crate");
        EXPECT_NEAR(row.time, double(f + 1) / 30, 1e-9);
        for (double v : row.values) EXPECT_TRUE(std::isfinite(v)) << "frame " << row.frame;
        // The body keeps a unit quaternion (RigidBody::setState normalises; drift turns it by
        // a unit quaternion): 1e-6 is far above double rounding over a few hundred steps.
        const double q = std::sqrt(row.values[3] * row.values[3] + row.values[4] * row.values[4]
                                   + row.values[5] * row.values[5] + row.values[6] * row.values[6]);
        EXPECT_NEAR(q, 1.0, 1e-6) << "frame " << row.frame;
    }
    // The crate starts at rest with its centre at y = 0.17 m and falls: after one frame
    // (1/30 s) free fall alone takes it g t^2 / 2 = 5.4 mm down, and it is still above the
    // water (its bottom 2 cm up), so it has moved down by at least half of that.
    EXPECT_LT(rows[0].values[1], 0.17 - 0.0027);
    EXPECT_LT(rows[0].values[8], 0.0) << "moving down after the first frame";
    // A crate of half the water's density floats: it sinks to about half its height (3 cm)
    // into water 12 cm deep, centre near 0.12 m, and never reaches the floor (its centre
    // would be at 3 cm there). Bound: its centre stays above 8 cm, well clear of the floor.
    double lowest = 1;
    for (const BodyRow& row : rows) lowest = std::min(lowest, row.values[1]);
    EXPECT_GT(lowest, 0.08);
    EXPECT_LT(rows.back().values[1], 0.17 - 0.01) << "it fell into the water";

    // stats.h5 holds the same rows, bit for bit (both are written from the same numbers).
    const std::vector<BodyRow> h5 =
        ghostfx::vdbio::readStatsBodies((mDir / "out" / "stats.h5").string());
    ASSERT_EQ(h5.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(h5[i].frame, rows[i].frame);
        EXPECT_EQ(h5[i].name, rows[i].name);
        EXPECT_EQ(h5[i].time, rows[i].time);
        EXPECT_EQ(h5[i].values, rows[i].values) << "row " << i;
    }
}

TEST_F(Bodies, ResumedRunContinuesTheRows)
{
    Json scene = crateScene(4);
    const std::string path = write(scene);
    const fs::path a = mDir / "a", b = mDir / "b";
    ASSERT_EQ(run("run " + path + " --out " + a.string() + " -q").code, 0);
    ASSERT_EQ(run("run " + path + " --out " + b.string() + " -q --frames 1-2").code, 0);
    const Result resumed = run("run " + path + " --out " + b.string() + " -q --resume "
                               + (b / "checkpoint.0002.h5").string());
    ASSERT_EQ(resumed.code, 0) << resumed.err;
    // The rows of frames 1-2 are kept as written, bit for bit (the shortest text that reads
    // back as the same double), and 3-4 added once.
    const std::vector<BodyRow> resumedRows =
        ghostfx::vdbio::readBodiesCsv((b / "bodies.csv").string());
    const std::vector<BodyRow> straightRows =
        ghostfx::vdbio::readBodiesCsv((a / "bodies.csv").string());
    ASSERT_EQ(resumedRows.size(), 4u) << "4 rows, none repeated";
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(resumedRows[i].frame, int(i) + 1);
    for (std::size_t i = 0; i < 2; ++i)
        EXPECT_EQ(resumedRows[i].values, straightRows[i].values) << "frame " << i + 1;
    // Frames 3-4 simulated from the checkpoint: the solver's resumed body follows the
    // uninterrupted one within 1e-4 relative, not bit for bit (the bound and the gap of
    // tests/ghost/test_rigid_bodies.cc, AResumedRunAndEitherThreadCountGiveTheSameBody; here
    // the 9th digit differs). The checkpoint carries the body's state (body_1_* reals).
    for (std::size_t i = 2; i < 4; ++i) {
        for (std::size_t v = 0; v < ghostfx::vdbio::BODY_VALUES; ++v) {
            const double straight = straightRows[i].values[v];
            const double scale = std::max(std::abs(straight), 1e-2);
            EXPECT_NEAR(resumedRows[i].values[v], straight, 1e-4 * scale)
                << "frame " << i + 1 << ", column " << ghostfx::vdbio::bodyColumns()[3 + v];
        }
    }
    const std::string fingerprint = ghostfx::vdbio::readScene(path).simulationFingerprint();
    const auto saved =
        ghostfx::vdbio::readCheckpointStates((b / "checkpoint.0002.h5").string(), fingerprint);
    ASSERT_EQ(saved.size(), 1u);
    EXPECT_EQ(saved[0].real("body_1_y"), straightRows[1].values[1])
        << "frame 2's centre, as written";
}

TEST_F(Bodies, VolumeFileHoldsEachSolidWhereItIs)
{
    Json scene = crateScene(3);
    scene["outputs"]["volume"] = Json::parse(R"({ "grids": ["surface"], "solids": true })");
    const std::string path = write(scene);
    const Result r = run("run " + path + " --out " + (mDir / "out").string() + " -q");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<BodyRow> rows =
        ghostfx::vdbio::readBodiesCsv((mDir / "out" / "bodies.csv").string());
    ASSERT_EQ(rows.size(), 3u);
    const openvdb::FloatGrid::Ptr crate = readGrid(mDir / "out" / "liquid.0003.vdb", "crate");
    ASSERT_TRUE(crate);
    EXPECT_TRUE(readGrid(mDir / "out" / "liquid.0003.vdb", "tank")) << "static solids too";
    EXPECT_EQ(crate->getGridClass(), openvdb::GRID_LEVEL_SET);
    // The same crate standing still: its grid is the scene's level set as it is.
    Json still = scene;
    still["solids"][1].erase("dynamic");
    still["settings"]["frame_range"] = {1, 1};
    ASSERT_EQ(
        run("run " + write(still, "still.json") + " --out " + (mDir / "still").string() + " -q")
            .code,
        0);
    const openvdb::FloatGrid::Ptr given = readGrid(mDir / "still" / "liquid.0001.vdb", "crate");
    ASSERT_TRUE(given);
    // The given level set holds the box's 0.1 x 0.06 x 0.1 m = 6e-4 m^3 less what its 1 cm
    // voxels round off at the edges and corners (OpenVDB's level-set measure): within 5 %.
    const double givenVolume = openvdb::tools::levelSetVolume(*given);
    EXPECT_NEAR(givenVolume, 6e-4, 0.05 * 6e-4);
    // Placed where the body is (turned and moved, the band rebuilt), it keeps that volume
    // within the issue's 2 %.
    const double volume = openvdb::tools::levelSetVolume(*crate);
    EXPECT_NEAR(volume, givenVolume, 0.02 * givenVolume);
    // At its place: the centre of the voxels inside is the body's centre of mass of frame 3,
    // within half a voxel (5 mm) on every axis. The inside is sdfInteriorMask's (the narrow
    // band's negative voxels and the interior tiles).
    const auto mask = openvdb::tools::sdfInteriorMask(*crate);
    openvdb::Vec3d sum(0.0);
    double count = 0;
    for (auto it = mask->cbeginValueOn(); it; ++it) {
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        const double n = double(box.volume());
        sum += crate->indexToWorld(box.getCenter()) * n;
        count += n;
    }
    const openvdb::Vec3d centre = sum / count;
    const BodyRow& last = rows.back();
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(centre[a], last.values[a], 0.005) << "axis " << a;
}

TEST_F(Bodies, BadKeysAreOneLineErrors)
{
    auto errorFor = [&](const std::function<void(Json&)>& change) {
        Json scene = crateScene(1);
        change(scene);
        return errorLine("run " + write(scene) + " --out " + (mDir / "out").string());
    };
    const std::string file = (mDir / "scene.json").string();
    EXPECT_EQ(
        errorFor([](Json& s) { s["solids"][1]["dynamic"]["mass"] = 12.5; }),
        "ghostfx: error: scene '" + file
            + "': solids[1].dynamic: expected exactly one of 'density' (kg/m^3) or 'mass' (kg)\n");
    EXPECT_EQ(errorFor([](Json& s) { s["solids"][1]["dynamic"]["restitution"] = 2; }),
              "ghostfx: error: scene '" + file
                  + "': solids[1].dynamic.restitution = 2: expected a number in [0, 1]\n");
    EXPECT_EQ(errorFor([](Json& s) { s["solids"][1]["dynamic"]["friction"] = -1; }),
              "ghostfx: error: scene '" + file
                  + "': solids[1].dynamic.friction = -1: expected a number >= 0\n");
    EXPECT_EQ(errorFor([](Json& s) { s["solids"][1]["dynamic"]["density"] = 0; }),
              "ghostfx: error: scene '" + file
                  + "': solids[1].dynamic.density = 0: expected a number > 0\n");
    EXPECT_EQ(errorFor([](Json& s) {
                  s["solids"][1]["velocity"] = {0, 1, 0};
              }),
              "ghostfx: error: scene '" + file
                  + "': solids[1].velocity: a dynamic solid is moved by the liquid and its "
                    "contacts: expected no 'velocity' beside 'dynamic' (its start velocity is "
                    "dynamic.velocity)\n");
    EXPECT_EQ(errorFor([](Json& s) {
                  s["solids"][1]["motion"] = Json::parse(R"({ "keys": [ { "time": 0 } ] })");
              }),
              "ghostfx: error: scene '" + file
                  + "': solids[1].motion: a dynamic solid is moved by the liquid and its "
                    "contacts: expected no 'motion' beside 'dynamic'\n");
    EXPECT_EQ(
        errorFor([](Json& s) {
            s["solids"][1]["sequence"] = Json::parse(R"({ "file": "c.$F4.vdb", "grid": "c" })");
        }),
        "ghostfx: error: scene '" + file
            + "': solids[1].sequence: a dynamic solid is moved by the liquid and its "
              "contacts: expected no 'sequence' beside 'dynamic' (its shape sets its mass)\n");
    EXPECT_EQ(errorFor([](Json& s) { s["solids"][1]["dynamic"]["densty"] = 500; }),
              "ghostfx: error: scene '" + file
                  + "': solids[1].dynamic.densty: unknown key (did you mean 'density'?)\n");
    EXPECT_EQ(errorFor([](Json& s) { s["settings"]["method"] = "basic"; }),
              "ghostfx: error: scene '" + file
                  + "': solids[1].dynamic: solid 'crate' is dynamic, which settings.method "
                    "'basic' cannot simulate: expected a solid without 'dynamic'\n");
    EXPECT_EQ(
        errorFor(
            [](Json& s) {
        s["settings"]["method"] = "gas";
        s.erase("liquids");
        s["gas_sources"] = Json::parse(
            R"([ { "geometry": { "box": { "min": [0.1, 0, 0.1], "max": [0.2, 0.04, 0.2] } } } ])");
        }),
        "ghostfx: error: scene '" + file
            + "': solids[1].dynamic: solid 'crate' is dynamic, which a gas scene cannot "
              "simulate: expected a solid without 'dynamic'\n");
    EXPECT_FALSE(fs::exists(mDir / "out" / "bodies.csv")) << "nothing written before the error";
}
