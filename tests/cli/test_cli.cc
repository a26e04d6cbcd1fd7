/// @file   test_cli.cc
/// @brief  `ghostfx` end to end: a small scene run through the real executable, its outputs read
///         back, resume equality, Ctrl-C, every input error's message and exit code, and
///         "model only what the scene requires".
#include "LiquidScene.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/Scene.h>

#include "CliHarness.h"
#include "common/Expect.h"
#include "common/StateDiff.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <sstream>
#include <sys/wait.h>

namespace fs = std::filesystem;
using namespace ghostfx;
using vdbio::Json;

namespace {

using ghostfx::testing::CliTest;
using ghostfx::testing::gridBytes;
using ghostfx::testing::pointCount;
using ghostfx::testing::Result;
using ghostfx::testing::signalAndWait;
using ghostfx::testing::slurp;
using ghostfx::testing::waitForFile;

/// "" when the checkpoints `a` and `b` of the scene `scene` hold the same state bit for bit,
/// else what differs first.
std::string checkpointDifference(const std::string& scene, const fs::path& a, const fs::path& b)
{
    return ghostfx::testing::checkpointDifference(scene, a, b);
}

/// Each test gets a fresh folder holding a small scene: a 0.3 m tank with a 0.1 m cube of water
/// at 0.015 m spacing (~250 liquid particles), 10 fixed substeps per frame.
class Cli : public CliTest
{
protected:
    void SetUp() override { mDir = ghostfx::testing::freshTestDir("cli"); }

    /// Start `ghostfx run <scene> --out <out> --progress none` in the background, its stderr into
    /// the test's folder; its pid (0 if it did not start).
    pid_t spawnRun(const std::string& scene, const std::string& out) const
    {
        return spawn({"run", scene, "--out", out, "--progress", "none"}, mDir / "run_stderr.txt");
    }

    static Json smallScene()
    {
        return Json::parse(R"({
            "ghostfx_scene": 1,
            "settings": { "method": "ghost", "spacing": 0.015, "substeps": 10, "frame_range": [1, 3],
                          "stiffness": 2000, "seed": 7 },
            "solids": [ { "name": "tank",
                          "geometry": { "container": { "min": [0, 0, 0], "max": [0.3, 0.3, 0.3] } } } ],
            "liquids": [ { "name": "water",
                           "geometry": { "box": { "min": [0.0, 0.0, 0.0], "max": [0.12, 0.12, 0.3] } } } ],
            "outputs": { "checkpoint": { "every": 2 } }
        })");
    }
};

} // namespace

TEST_F(Cli, RunsASceneToAFrameSequence)
{
    const Result ok =
        run("run " + write(smallScene()) + " --out " + (mDir / "out").string() + " --progress log");
    ASSERT_EQ(ok.code, 0) << ok.err;
    EXPECT_CONTAINS(ok.err, "frame 3/3");
    const fs::path out = mDir / "out";
    for (int f = 1; f <= 3; ++f) {
        char name[64];
        std::snprintf(name, sizeof(name), "liquid.%04d.vdb", f);
        ASSERT_TRUE(fs::exists(out / name)) << name;
        std::snprintf(name, sizeof(name), "liquid_points.%04d.vdb", f);
        ASSERT_TRUE(fs::exists(out / name)) << name;
    }
    // Checkpoints every 2 frames and at the last frame; statistics in HDF5 and CSV.
    EXPECT_TRUE(fs::exists(out / "checkpoint.0002.h5"));
    EXPECT_TRUE(fs::exists(out / "checkpoint.0003.h5"));
    EXPECT_TRUE(fs::exists(out / "stats.h5"));
    const std::string csv = slurp(out / "stats.csv");
    EXPECT_EQ(csv.rfind("frame,step,time,dt,count_liquid", 0), 0u) << csv.substr(0, 200);
    // 3 frames x 10 substeps = 30 rows plus the header.
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 31);
    // No temporary file is left behind by the atomic writes.
    for (const auto& entry : fs::directory_iterator(out)) {
        EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
    }

    // The volume file: three grids with the classes Houdini and Blender expect, no point grid.
    openvdb::io::File volume((out / "liquid.0003.vdb").string());
    volume.open();
    std::set<std::string> names;
    for (auto it = volume.beginName(); it != volume.endName(); ++it) names.insert(*it);
    EXPECT_EQ(names, (std::set<std::string>{"density", "surface", "vel"}));
    EXPECT_EQ(volume.readGrid("surface")->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_EQ(volume.readGrid("density")->getGridClass(), openvdb::GRID_FOG_VOLUME);
    volume.close();

    // Points: liquid only (the run also holds ghost air and ghost solid particles).
    const vdbio::CheckpointHeader header =
        vdbio::readCheckpointHeader((out / "checkpoint.0003.h5").string());
    EXPECT_EQ(header.frame, 3);
    EXPECT_GT(header.countPerKind.at("ghost_solid"), 0u);
    EXPECT_EQ(pointCount(out / "liquid_points.0003.vdb"), header.countPerKind.at("liquid"));
    std::printf("[measured] %zu liquid, %zu air, %zu solid ghosts after 3 frames\n",
                header.countPerKind.at("liquid"), header.countPerKind.at("ghost_air"),
                header.countPerKind.at("ghost_solid"));
}

TEST_F(Cli, ResumedRunMatchesAnUninterruptedOneBitForBit)
{
    Json scene = smallScene();
    scene["settings"]["frame_range"] = {1, 4};
    // An emitter and a moving solid exercise every piece of state that must survive.
    scene["emitters"] = Json::parse(
        R"([{ "geometry": { "box": { "min": [0.2, 0.2, 0.1], "max": [0.26, 0.26, 0.2] } },
                                          "velocity": [0, -0.5, 0], "start": 0, "end": 1 }])");
    const std::string path = write(scene);
    const fs::path a = mDir / "a", b = mDir / "b";
    // The run says what the emitter pours: 0.06 x 0.1 m across its velocity at 0.5 m/s is
    // 60 cm^2 and 3 kg/s of water, less what the level set's trilinear edges round off (58.2
    // cm^2 at this scene's voxels; bound 5 %).
    const Result told = run("run " + path + " --out " + (mDir / "told").string() + " --frames 1-1");
    ASSERT_EQ(told.code, 0) << told.err;
    const std::size_t at = told.err.find("emitter 'emitters[0]': 0.5 m/s through ");
    ASSERT_NE(at, std::string::npos) << told.err;
    double area = 0, rate = 0;
    ASSERT_EQ(std::sscanf(told.err.c_str() + at,
                          "emitter 'emitters[0]': 0.5 m/s through %lf cm^2 = %lf kg/s", &area,
                          &rate),
              2)
        << told.err;
    EXPECT_NEAR(area, 60.0, 3.0);
    EXPECT_NEAR(rate, 1000 * 0.5 * area * 1e-4, 0.01);
    EXPECT_CONTAINS(told.err.substr(at), "kg/s from 0 s to 1 s");
    ASSERT_EQ(run("run " + path + " --out " + a.string() + " -q").code, 0);
    ASSERT_EQ(run("run " + path + " --out " + b.string() + " -q --frames 1-2").code, 0);
    fs::remove(b / "liquid_points.0003.vdb");
    const Result resumed = run("run " + path + " --out " + b.string() + " -q --resume "
                               + (b / "checkpoint.0002.h5").string());
    ASSERT_EQ(resumed.code, 0) << resumed.err;

    EXPECT_EQ(checkpointDifference(path, a / "checkpoint.0004.h5", b / "checkpoint.0004.h5"), "");
    EXPECT_EQ(pointCount(a / "liquid_points.0004.vdb"), pointCount(b / "liquid_points.0004.vdb"));
    EXPECT_TRUE(fs::exists(b / "liquid_points.0003.vdb")) << "the resumed run writes frames 3-4";
    // The statistics continue where the checkpoint left off: 4 frames x 10 steps.
    const std::string csv = slurp(b / "stats.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 41);
}

TEST_F(Cli, MovingEmitterRunsAndResumesBitForBit)
{
    // A hose sweeping the tank's floor: the emitter's `motion` keys move it 0.12 m along x over
    // the run while it pours 0.5 m/s down. The key is read (an unknown key is an error), the
    // run pours, a resumed run continues it bit for bit (the keys are part of the scene), and a
    // checkpoint of other keys is refused.
    Json scene = smallScene();
    scene["settings"]["frame_range"] = {1, 4};
    scene.erase("liquids");
    scene["emitters"] = Json::parse(
        R"([{ "name": "hose", "velocity": [0, -0.5, 0],
              "geometry": { "box": { "min": [0.03, 0.1, 0.12], "max": [0.09, 0.16, 0.18] } },
              "motion": { "keys": [ { "time": 0, "translate": [0, 0, 0] },
                                    { "time": 0.2, "translate": [0.12, 0, 0], "rotate": [0, 0, 10] } ] } }])");
    const std::string path = write(scene);
    const fs::path a = mDir / "a", b = mDir / "b";
    const Result full = run("run " + path + " --out " + a.string() + " --progress log");
    ASSERT_EQ(full.code, 0) << full.err;
    EXPECT_CONTAINS(full.err, "emitter 'hose': 0.5 m/s through ");
    const vdbio::CheckpointHeader header =
        vdbio::readCheckpointHeader((a / "checkpoint.0004.h5").string());
    // 0.133 s at 0.5 m/s through about 36 cm^2 is 2.4e-4 m^3, some 70 particles at 0.015 m:
    // at least half of them must be there.
    EXPECT_GT(header.countPerKind.at("liquid"), 35u);

    ASSERT_EQ(run("run " + path + " --out " + b.string() + " -q --frames 1-2").code, 0);
    const Result resumed = run("run " + path + " --out " + b.string() + " -q --resume "
                               + (b / "checkpoint.0002.h5").string());
    ASSERT_EQ(resumed.code, 0) << resumed.err;
    EXPECT_EQ(checkpointDifference(path, a / "checkpoint.0004.h5", b / "checkpoint.0004.h5"), "");

    // Other keys are another scene: its checkpoint does not resume this one.
    const std::string line =
        errorLine("run " + path + " -D emitters[0].motion.keys[1].translate=[0.1,0,0] --out "
                  + b.string() + " --resume " + (b / "checkpoint.0002.h5").string());
    EXPECT_CONTAINS(line, "checkpoint.0002.h5' was written with different settings");
}

TEST_F(Cli, CheckpointFromOtherSettingsIsRefused)
{
    const std::string path = write(smallScene());
    ASSERT_EQ(run("run " + path + " --out " + (mDir / "out").string() + " -q --frames 1-2").code,
              0);
    const std::string line =
        errorLine("run " + path + " -D settings.stiffness=5000 --out " + (mDir / "out").string()
                  + " --resume " + (mDir / "out" / "checkpoint.0002.h5").string());
    EXPECT_CONTAINS(line, "checkpoint.0002.h5' was written with different settings");
    EXPECT_CONTAINS(line, "stiffness");
    EXPECT_CONTAINS(line, "2000");
    EXPECT_CONTAINS(line, "5000");
}

// A setting whose declaration says a checkpoint need not match it (the blow-up bound
// max_speed) may change on resume; the others may not (above).
TEST_F(Cli, ResumeMayChangeASettingDeclaredFreeOnResume)
{
    const std::string path = write(smallScene());
    ASSERT_EQ(run("run " + path + " --out " + (mDir / "out").string() + " -q --frames 1-2").code,
              0);
    const Result resumed =
        run("run " + path + " -D settings.max_speed=100 --out " + (mDir / "out").string()
            + " -q --frames 1-3 --resume " + (mDir / "out" / "checkpoint.0002.h5").string());
    EXPECT_EQ(resumed.code, 0) << resumed.err;
}

TEST_F(Cli, BadInputGetsOneClearLine)
{
    const std::string out = " --out " + (mDir / "out").string();
    EXPECT_CONTAINS(errorLine("run " + (mDir / "nope.json").string() + out),
                    "nope.json': cannot open the file");

    const std::string good = write(smallScene());
    // (arguments after "run <scene> --out <folder>", what the one error line says)
    const std::pair<const char*, const char*> refusals[] = {
        {" -D settings.stifness=5000",
         "settings.stifness: unknown key (did you mean 'stiffness'?)"},
        {" -D settings.stiffness=-1", "settings.stiffness = -1: expected a number > 0"},
        {" -D settings.cfl=50", "settings.cfl = 50: expected a number in [0.001, 2]"},
        {" -D settings.shifting=50", "settings.shifting = 50: expected a number in [0, 20]"},
        {" -D settings.initial_relaxation=2.5",
         "settings.initial_relaxation = 2.5: expected a whole number in [0, 1000] (passes)"},
        {" -D settings.pressure=iisph",
         "settings.pressure = \"iisph\": expected one of 'tait', 'dfsph' (did you mean 'dfsph'?)"},
        {" -D settings.sampling_relaxation=lloyd",
         "settings.sampling_relaxation = \"lloyd\": expected one of 'sb12', 'packing'"},
        {" -D settings.dfsph.density_eror=0.01",
         "settings.dfsph.density_eror: unknown key (did you mean 'density_error'?)"},
        {" -D settings.dfsph.density_relaxation=0", "settings.dfsph.density_relaxation = 0: "
                                                    "expected a number in [1e-6, 1]"},
        {" -D settings.dfsph.wall_pressure=mirror", "settings.dfsph.wall_pressure: unknown key"},
        {" -D settings.dfsph.air_density=half",
         "settings.dfsph.air_density = \"half\": expected one of 'full', 'fill'"},
        {" -D settings.dfsph.air_resampling=frame",
         "settings.dfsph.air_resampling = \"frame\": expected one of 'step', 'time'"},
        {" -D settings.dfsph.kept_gradients_gb=-1",
         "settings.dfsph.kept_gradients_gb = -1: expected a number in [0, 1e6] (GiB)"},
        {" -D settings.method=basic -D settings.pressure=dfsph",
         "liquid setting pressure = 'dfsph' with method 'basic': expected 'tait'"},
        {" -D settings.method=gas", "liquids: a 'gas' scene simulates gas only: liquids, emitters "
                                    "and heaters need a liquid method ('ghost' or 'basic'"},
        {" -D settings.gas.kappa=2",
         "settings.gas: gas settings need a gas method or heaters (boiling)"},
        {" -D 'liquids[0].geometry={\"file\":\"none.vdb\",\"grid\":\"x\"}'",
         "none.vdb' does not exist"},
        {" -D liquids[0].viscosity=-1", "liquid 'water': viscosity = -1: expected a number in "
                                        "[0, 100000] (m^2/s), as settings.viscosity"},
        {" -D 'liquids[0].viscosity=\"thick\"'", "liquids[0].viscosity"},
        {" --frames 5-2", "--frames '5-2': expected 1 <= first <= last"},
        // Frame numbers that do not fit: refused, not wrapped into "nothing to do" with exit 0.
        {" --frames 1-3000000000", "--frames '1-3000000000': expected A-B (e.g. 1-48) or a last "
                                   "frame, whole numbers up to 9999999"},
        {" --frames 1-2x", "--frames '1-2x': expected A-B"},
        {" -D settings.frame_range=[1,3000000000]",
         "settings.frame_range = [1,3000000000]: expected [first, last] with 1 <= first <= last <= "
         "9999999"},
        {" -D settings.frame_range=[1,99999999999999999999]",
         "settings.frame_range = [1,1e+20]: expected [first, last]"},
    };
    for (const auto& [args, expected] : refusals)
        EXPECT_CONTAINS(errorLine("run " + good + out + args), expected);
    // Liquid entirely inside the tank wall: no particles.
    EXPECT_CONTAINS(errorLine("run " + good + out
                              + " -D liquids[0].geometry.box.min=[-0.04,0.05,0.05]"
                              + " -D liquids[0].geometry.box.max=[-0.01,0.1,0.1]"),
                    "liquid 'water' (box) gives no particles at spacing 0.015 m");
    // Unwritable output folder: a file where the folder should be.
    std::ofstream(mDir / "afile") << "x";
    EXPECT_CONTAINS(errorLine("run " + good + " --out " + (mDir / "afile").string()),
                    "output folder '" + (mDir / "afile").string()
                        + "': exists and is not a folder");
    // Nothing was written by any of the failed runs.
    EXPECT_FALSE(fs::exists(mDir / "out") && !fs::is_empty(mDir / "out"));
}

TEST_F(Cli, FixedStepBeyondTheStabilityLimitIsWarnedAboutBeforeTheFirstStep)
{
    const std::string path = write(smallScene());
    const std::string out = " --out " + (mDir / "out").string() + " -q --frames 1-1";
    // 1 fps and one substep: dt = 1 s against a limit of a few ms (spacing 0.015 m, sound
    // speed 3.7 m/s): the warning names both numbers and the substeps that would do.
    const Result bad =
        run("run " + path + out + " -D settings.frame_rate=1 -D settings.substeps=1");
    EXPECT_CONTAINS(bad.err, "ghostfx: warning: scene '" + path
                                 + "': the fixed step 1 s (frame_rate 1, substeps 1) is ");
    EXPECT_CONTAINS(bad.err, "x the stability limit 0.00");
    EXPECT_CONTAINS(bad.err, "use substeps >= ");
    // The scene's own 10 substeps at 30 fps (dt 3.3 ms) are within it: no warning.
    const Result good = run("run " + path + out);
    EXPECT_EQ(good.code, 0) << good.err;
    EXPECT_EQ(good.err.find("warning"), std::string::npos) << good.err;
}

TEST_F(Cli, DfsphSolvesStoppedAtTheIterationCapAreWarnedAbout)
{
    // One iteration per solve and a limit of 1e-5 cannot be met while the cube collapses: the
    // frame's warning names the cap and, per solve, the mean and the largest error of one
    // particle against the limit and its peak factor.
    const std::string path = write(smallScene());
    const Result r =
        run("run " + path + " --out " + (mDir / "out").string()
            + " -q --frames 1-1 -D settings.pressure=dfsph -D settings.substeps=0"
              " -D settings.dfsph.max_iterations=1 -D settings.dfsph.density_error=1e-5"
              " -D settings.dfsph.divergence_error=1e-5");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_CONTAINS(r.err, "ghostfx: warning: scene '" + path + "', frame 1: ");
    EXPECT_CONTAINS(r.err, "DFSPH solves stopped at dfsph.max_iterations = 1 above their error "
                           "limit (last: density mean ");
    EXPECT_CONTAINS(r.err, "against 1e-05 and 30 x that; divergence ");
}

TEST_F(Cli, DfsphGradientsOverTheirMemoryLimitAreWarnedAboutOnce)
{
    // A limit of about 1 kB cannot hold the small scene's kept gradients (hundreds of kB): the
    // run recomputes them, finishes, and says so once, with the size it would have needed.
    const std::string path = write(smallScene());
    const Result r = run("run " + path + " --out " + (mDir / "out").string()
                         + " -q --frames 1-2 -D settings.pressure=dfsph -D settings.substeps=0"
                           " -D settings.dfsph.kept_gradients_gb=1e-6");
    EXPECT_EQ(r.code, 0) << r.err;
    const std::string warning = "ghostfx: warning: scene '" + path
                                + "', frame 1: the DFSPH solves recompute their kernel "
                                  "gradients: keeping them would take ";
    EXPECT_CONTAINS(r.err, warning);
    EXPECT_CONTAINS(r.err, "above dfsph.kept_gradients_gb = 1e-06");
    EXPECT_EQ(r.err.find("the DFSPH solves recompute", r.err.find(warning) + warning.size()),
              std::string::npos)
        << "warned more than once: " << r.err;
    // At the default limit: no warning.
    const Result quiet = run("run " + path + " --out " + (mDir / "out2").string()
                             + " -q --frames 1-1 -D settings.pressure=dfsph -D "
                               "settings.substeps=0");
    EXPECT_EQ(quiet.code, 0) << quiet.err;
    EXPECT_EQ(quiet.err.find("recompute"), std::string::npos) << quiet.err;
}

TEST_F(Cli, SolidThinnerThanTheKernelSupportIsWarnedAbout)
{
    // The tank's walls default to one kernel radius (3 h = 0.045 m): no warning (checked by
    // the test above). Walls of 0.02 m hold less than half the ghost-solid layer: warned, with
    // the solid's name, the depth needed and the share of its surface.
    Json scene = smallScene();
    scene["solids"][0]["geometry"]["container"]["wall"] = 0.02;
    const std::string path = write(scene);
    const Result r = run("run " + path + " --out " + (mDir / "out").string() + " -q --frames 1-1");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_CONTAINS(r.err,
                    "ghostfx: warning: scene '" + path
                        + "': solid 'tank' is thinner than the kernel support 0.045 m over ");
    EXPECT_CONTAINS(r.err, "make it at least 0.045 m thick");
}

TEST_F(Cli, CtrlCFinishesTheFrameWritesACheckpointAndExitsNonZero)
{
    Json scene = smallScene();
    scene["settings"]["frame_range"] = {1, 400};
    const std::string path = write(scene);
    const std::string out = (mDir / "out").string();
    const pid_t pid = spawnRun(path, out);
    ASSERT_GT(pid, 0);
    // Wait for the first frame, then interrupt.
    waitForFile(fs::path(out) / "liquid.0001.vdb", std::chrono::seconds(120),
                std::chrono::milliseconds(50));
    const int status = signalAndWait(pid, SIGINT);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    // The checkpoint of the last finished frame is there and names that frame.
    int last = 0;
    for (const auto& e : fs::directory_iterator(out)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("checkpoint.", 0) == 0)
            last = std::max(last, vdbio::readCheckpointHeader(e.path().string()).frame);
    }
    ASSERT_GE(last, 1);
    EXPECT_LT(last, 400);
    // Frames are written while the next one simulates, and finished before the checkpoint:
    // every frame up to the checkpoint's is on disk.
    for (int f = 1; f <= last; ++f) {
        char name[64];
        std::snprintf(name, sizeof(name), "liquid.%04d.vdb", f);
        EXPECT_TRUE(fs::exists(fs::path(out) / name)) << name;
    }
    std::printf("[measured] interrupted after frame %d of 400\n", last);
}

TEST_F(Cli, KilledRunLeavesOnlyCompleteFrames)
{
    // kill -9 while frames are being written (the writer thread builds frame N's files while
    // frame N + 1 simulates): every frame file on disk must be whole, and the frames on disk a
    // gapless run from the first. Files are written to a hidden temporary beside the target and
    // renamed (vdbio/AtomicFile.h), so a kill leaves at most such a temporary, never a part of
    // a frame under its own name.
    Json scene = smallScene();
    scene["settings"]["frame_range"] = {1, 400};
    scene["outputs"]["preview"] = {{"file", "preview.$F4.exr"}, {"width", 64}, {"height", 36}};
    const std::string path = write(scene);
    const fs::path out = mDir / "out";
    const pid_t pid = spawnRun(path, out.string());
    ASSERT_GT(pid, 0);
    waitForFile(out / "liquid.0004.vdb", std::chrono::seconds(120), std::chrono::milliseconds(5));
    const int status = signalAndWait(pid, SIGKILL);
    ASSERT_TRUE(WIFSIGNALED(status));

    std::map<std::string, std::vector<int>> frames; // pattern -> frame numbers on disk
    int hidden = 0;
    for (const auto& e : fs::directory_iterator(out)) {
        const std::string name = e.path().filename().string();
        if (name[0] == '.') { // a temporary the kill interrupted
            EXPECT_NE(name.find(".tmp"), std::string::npos) << name;
            ++hidden;
            continue;
        }
        const std::size_t dot = name.find('.');
        const std::string stem = name.substr(0, dot);
        if (name.size() > 4 && name.substr(name.size() - 4) == ".vdb") {
            EXPECT_FALSE(gridBytes(e.path()).empty()) << name; // opens and reads whole
        } else if (stem == "checkpoint") {
            EXPECT_GE(vdbio::readCheckpointHeader(e.path().string()).frame, 1) << name;
        } else if (stem == "preview") {
            EXPECT_GT(fs::file_size(e.path()), 0u) << name;
        }
        if (stem == "liquid" || stem == "liquid_points" || stem == "preview") {
            frames[stem].push_back(std::atoi(name.c_str() + dot + 1));
        }
    }
    ASSERT_FALSE(frames["liquid"].empty());
    for (auto& [stem, numbers] : frames) {
        std::sort(numbers.begin(), numbers.end());
        for (std::size_t k = 0; k < numbers.size(); ++k) {
            EXPECT_EQ(numbers[k], int(k) + 1) << stem << ": frames on disk have a gap";
        }
    }
    std::printf("[measured] killed after %zu volume frames (%zu points files, %zu previews), "
                "%d temporaries left\n",
                frames["liquid"].size(), frames["liquid_points"].size(), frames["preview"].size(),
                hidden);
}

TEST_F(Cli, OverlappedOutputEqualsSerialOutput)
{
    // Points with ghosts, every volume grid and a preview: what the writer thread builds from
    // its snapshot must be what the run would have written between steps.
    Json scene = smallScene();
    scene["outputs"]["points"] = {{"ghosts", true}};
    scene["outputs"]["volume"] = {{"grids", {"surface", "density", "vel"}}};
    scene["outputs"]["preview"] = {{"file", "preview.$F4.exr"}, {"width", 64}, {"height", 36}};
    const std::string path = write(scene);
    const fs::path overlapped = mDir / "overlapped", serial = mDir / "serial";
    ASSERT_EQ(run("run " + path + " -q --out " + overlapped.string()).code, 0);
    ASSERT_EQ(run("run " + path + " -q --serial-output --out " + serial.string()).code, 0);
    for (int f = 1; f <= 3; ++f) {
        for (const char* pattern : {"liquid_points.%04d.vdb", "liquid.%04d.vdb"}) {
            char name[64];
            std::snprintf(name, sizeof(name), pattern, f);
            const auto a = gridBytes(overlapped / name), b = gridBytes(serial / name);
            EXPECT_FALSE(a.empty()) << name;
            EXPECT_TRUE(a == b) << name << " differs between overlapped and serial output";
        }
        char exr[64];
        std::snprintf(exr, sizeof(exr), "preview.%04d.exr", f);
        EXPECT_EQ(slurp(overlapped / exr), slurp(serial / exr)) << exr;
    }
    EXPECT_EQ(checkpointDifference(path, overlapped / "checkpoint.0003.h5",
                                   serial / "checkpoint.0003.h5"),
              "");

    // A frame that cannot be written stops the run with one line, as without overlap.
    EXPECT_CONTAINS(errorLine("run " + path + " -q --out " + (mDir / "bad").string()
                              + " -D outputs.preview.grid=temperature"),
                    "outputs.preview.grid = 'temperature': the volume output has no such grid");
}

TEST_F(Cli, OnlyWhatTheSceneRequiresIsModelledAndWritten)
{
    // A liquid-only scene (no solids): no solid ghosts and no solid channels in the solver.
    Json scene = smallScene();
    scene.erase("solids");
    scene["settings"]["gravity"] = {0, 0, 0};
    const vdbio::Scene s = vdbio::readScene(write(scene));
    auto solver = cmd::makeLiquidSolver(s, cmd::liquidSettings(s, ghost::Method::Ghost));
    solver->advanceFrame();
    EXPECT_EQ(solver->count(sph::ParticleKind::GhostSolid), 0u);
    EXPECT_EQ(solver->count(sph::ParticleKind::Boundary), 0u);
    for (const std::string& c : solver->particles().vectorChannelNames()) {
        EXPECT_EQ(c.find("solid"), std::string::npos)
            << "channel " << c << " in a scene without solids";
    }
    for (const std::string& c : solver->particles().scalarChannelNames()) {
        EXPECT_EQ(c.find("solid"), std::string::npos)
            << "channel " << c << " in a scene without solids";
    }
    const double bytes =
        double(solver->particles().memoryBytes()) / double(solver->particles().size());
    std::printf("[measured] %.1f bytes per particle without solids\n", bytes);

    // Basic SPH: no ghost air at all.
    // (Basic SPH's Lennard-Jones walls need the CFL-limited step: it blows up at 10 fixed substeps.)
    const vdbio::Scene basic =
        vdbio::readScene(write(smallScene()), {"settings.method=basic", "settings.substeps=0"});
    auto b = cmd::makeLiquidSolver(basic, cmd::liquidSettings(basic, ghost::Method::Basic));
    b->advanceFrame();
    EXPECT_EQ(b->count(sph::ParticleKind::GhostAir), 0u);
    for (const std::string& c : b->particles().scalarChannelNames()) {
        EXPECT_EQ(c.find("air"), std::string::npos) << "channel " << c << " in a Basic SPH run";
    }

    // Only the grids asked for are made and written; points off means no points file.
    const std::string path = write(smallScene());
    ASSERT_EQ(
        run("run " + path + " --out " + (mDir / "out").string()
            + " -q --frames 1-1 -D 'outputs.volume.grids=[\"density\"]' -D outputs.points=false")
            .code,
        0);
    openvdb::io::File volume((mDir / "out" / "liquid.0001.vdb").string());
    volume.open();
    std::vector<std::string> names;
    for (auto it = volume.beginName(); it != volume.endName(); ++it) names.push_back(*it);
    volume.close();
    EXPECT_EQ(names, std::vector<std::string>{"density"});
    EXPECT_FALSE(fs::exists(mDir / "out" / "liquid_points.0001.vdb"));
}

TEST_F(Cli, InfoPreviewAndSceneFromRoleTaggedVdb)
{
    const std::string path = write(smallScene());
    const fs::path out = mDir / "out";
    ASSERT_EQ(run("run " + path + " --out " + out.string()
                  + " -q --frames 1-1 -D outputs.preview.width=160"
                  + " -D outputs.preview.height=90")
                  .code,
              0);
    EXPECT_TRUE(fs::exists(out / "preview.0001.exr"));
    const Result info = run("info " + (out / "liquid.0001.vdb").string());
    EXPECT_EQ(info.code, 0) << info.err;
    const std::string text = slurp(mDir / "stdout.txt");
    EXPECT_CONTAINS(text, "surface");
    EXPECT_CONTAINS(text, "density");
    // Points: per-attribute ranges, as vdbio::readPoints gives them (P in world space).
    EXPECT_EQ(run("info " + (out / "liquid_points.0001.vdb").string()).code, 0);
    const std::string pointsText = slurp(mDir / "stdout.txt");
    EXPECT_CONTAINS(pointsText, "  attribute ranges (min .. max, mean; P in world space, m):\n");
    EXPECT_CONTAINS(pointsText, "\n    P              [");
    EXPECT_CONTAINS(pointsText, "\n    id             "); // ids follow the solid ghosts'
    EXPECT_CONTAINS(pointsText, "\n    density        ");
    EXPECT_EQ(run("info " + (out / "checkpoint.0001.h5").string()).code, 0);
    EXPECT_CONTAINS(slurp(mDir / "stdout.txt"), "schema_version");
    // The frame holds density, surface and vel: by default the preview draws the liquid's
    // surface, and the extension chooses the format.
    EXPECT_EQ(run("preview " + (out / "liquid.0001.vdb").string() + " -o "
                  + (mDir / "p.exr").string() + " --width 64 --height 48")
                  .code,
              0);
    EXPECT_TRUE(fs::exists(mDir / "p.exr"));
    EXPECT_CONTAINS(slurp(mDir / "stdout.txt"), "grid 'surface' (level set");
    EXPECT_EQ(run("preview " + (out / "liquid.0001.vdb").string() + " -o "
                  + (mDir / "p.png").string() + " --width 64 --height 48 --grid density")
                  .code,
              0);
    EXPECT_CONTAINS(slurp(mDir / "stdout.txt"), "grid 'density' (fog volume");
    std::ifstream png(mDir / "p.png", std::ios::binary);
    char magic[4] = {};
    png.read(magic, 4);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG") << "a .png output is a PNG file";
    // The help says which formats it writes and how one is chosen.
    ASSERT_EQ(run("preview --help").code, 0);
    const std::string help = slurp(mDir / "stdout.txt");
    EXPECT_CONTAINS(help, ".exr");
    EXPECT_CONTAINS(help, ".png");
    EXPECT_CONTAINS(help, "extension chooses the format");
    EXPECT_CONTAINS(help, "default: 'surface'");
}

namespace {

/// A closed box [lo, hi] (m) as OBJ text.
std::string boxObj(const std::array<double, 3>& lo, const std::array<double, 3>& hi)
{
    std::ostringstream obj;
    for (int c = 0; c < 8; ++c) {
        obj << "v " << (c & 1 ? hi : lo)[0] << " " << (c & 2 ? hi : lo)[1] << " "
            << (c & 4 ? hi : lo)[2] << "\n";
    }
    obj << "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
    return obj.str();
}

/// A closed UV sphere of `radius` (m) around `centre`: 12 rings of 24 vertices and the poles.
std::string ballObj(const std::array<double, 3>& centre, double radius)
{
    constexpr int RINGS = 12, SLICES = 24;
    std::ostringstream obj;
    obj << "v " << centre[0] << " " << centre[1] + radius << " " << centre[2] << "\n";
    for (int i = 1; i < RINGS; ++i) {
        const double polar = M_PI * i / RINGS;
        for (int j = 0; j < SLICES; ++j) {
            const double azimuth = 2 * M_PI * j / SLICES;
            obj << "v " << centre[0] + radius * std::sin(polar) * std::cos(azimuth) << " "
                << centre[1] + radius * std::cos(polar) << " "
                << centre[2] + radius * std::sin(polar) * std::sin(azimuth) << "\n";
        }
    }
    obj << "v " << centre[0] << " " << centre[1] - radius << " " << centre[2] << "\n";
    const int south = 2 + (RINGS - 1) * SLICES;
    auto ring = [](int i, int j) { return 2 + (i - 1) * SLICES + j % SLICES; }; // 1-based
    for (int j = 0; j < SLICES; ++j) {
        obj << "f 1 " << ring(1, j + 1) << " " << ring(1, j) << "\n";
        for (int i = 1; i + 1 < RINGS; ++i) {
            obj << "f " << ring(i, j) << " " << ring(i, j + 1) << " " << ring(i + 1, j + 1) << " "
                << ring(i + 1, j) << "\n";
        }
        obj << "f " << south << " " << ring(RINGS - 1, j) << " " << ring(RINGS - 1, j + 1)
            << "\n";
    }
    return obj.str();
}

} // namespace

TEST_F(Cli, Mesh2SdfAppendsASolidAndALiquidIntoOneVdbScene)
{
    // Two meshes, two calls: a floor slab (solid) and a ball of water above it (liquid), both
    // into scene.vdb with --append; the .vdb is then a scene that runs with both.
    std::ofstream(mDir / "floor.obj") << boxObj({0, 0, 0}, {0.3, 0.05, 0.3});
    std::ofstream(mDir / "ball.obj") << ballObj({0.15, 0.12, 0.15}, 0.05);
    const std::string vdb = (mDir / "scene.vdb").string();
    const std::string common = " -o " + vdb + " --voxel-size 0.0075 --append";
    ASSERT_EQ(run("mesh2sdf " + (mDir / "floor.obj").string() + common + " --role solid --name floor")
                  .code,
              0);
    ASSERT_EQ(run("mesh2sdf " + (mDir / "ball.obj").string() + common + " --role liquid --name water")
                  .code,
              0);
    EXPECT_CONTAINS(slurp(mDir / "stdout.txt"), "(appended)");
    const auto grids = gridBytes(mDir / "scene.vdb");
    ASSERT_EQ(grids.size(), 2u);
    EXPECT_EQ(grids.count("floor"), 1u);
    EXPECT_EQ(grids.count("water"), 1u);

    // The same name again is one line and leaves the file as it was; --replace replaces it.
    EXPECT_CONTAINS(errorLine("mesh2sdf " + (mDir / "floor.obj").string() + common
                              + " --role liquid --name water"),
                    "'" + vdb + "' already has a grid 'water': expected a new name (--name) or "
                    "--replace");
    EXPECT_EQ(gridBytes(mDir / "scene.vdb"), grids);
    ASSERT_EQ(run("mesh2sdf " + (mDir / "ball.obj").string() + common
                  + " --role liquid --name water --replace")
                  .code,
              0);
    EXPECT_EQ(gridBytes(mDir / "scene.vdb").size(), 2u);

    // The scene: spacing twice the voxel (0.015 m); the log's frame line counts the media.
    const Result ran = run("run " + vdb + " --out " + (mDir / "out").string()
                           + " --frames 1-1 --progress log");
    ASSERT_EQ(ran.code, 0) << ran.err;
    std::size_t liquid = 0, air = 0, solid = 0;
    const std::size_t at = ran.err.find("frame 1/1: ");
    ASSERT_NE(at, std::string::npos) << ran.err;
    ASSERT_EQ(std::sscanf(ran.err.c_str() + ran.err.find("steps, ", at),
                          "steps, %zu liquid, %zu air, %zu solid ghosts", &liquid, &air, &solid),
              3)
        << ran.err;
    // The ball's volume (4/3 pi 0.05^3 = 5.24e-4 m^3, less the polygon's 2 %) over h^3 is 152
    // particles; the sampler packs 1.1-1.2 per h^3 (the 0.1 m cube of smallScene: 346 for
    // 296). Bounds 0.9-1.4 of it. The floor's ghosts: at least one layer under the ball.
    const double perCube = 5.24e-4 / (0.015 * 0.015 * 0.015);
    std::printf("[measured] .vdb scene from two appended meshes: %zu liquid (%.2f per h^3 of the "
                "ball), %zu air, %zu solid ghosts\n",
                liquid, liquid / perCube, air, solid);
    EXPECT_GT(liquid, 0.9 * perCube);
    EXPECT_LT(liquid, 1.4 * perCube);
    EXPECT_GT(solid, 100u);
}

namespace {

/// A hot source under a closed box of gas ([RYY15] fast solver), small enough for a test.
Json plumeScene()
{
    return Json::parse(R"({
        "ghostfx_scene": 1,
        "settings": { "method": "gas", "spacing": 0.04, "frame_range": [1, 3],
                      "gas": { "substeps": 2 } },
        "domain": { "kill_box": { "min": [-0.5, -0.1, -0.5], "max": [0.5, 1.5, 0.5] } },
        "gas_sources": [ { "name": "burner", "geometry": { "sphere": { "center": [0, 0.1, 0], "radius": 0.1 } },
                           "temperature": 600, "velocity": [0, 0.5, 0] } ],
        "outputs": { "checkpoint": { "every": 1 } }
    })");
}

} // namespace

TEST_F(Cli, GasPlumeRunsToDensityAndTemperatureVolumes)
{
    const std::string path = write(plumeScene(), "plume.json");
    const fs::path out = mDir / "out";
    const Result r = run("run " + path + " --out " + out.string() + " --progress log");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_CONTAINS(r.err, "gas, 0 ambient air");
    openvdb::io::File volume((out / "gas.0003.vdb").string());
    volume.open();
    std::set<std::string> names;
    for (auto it = volume.beginName(); it != volume.endName(); ++it) names.insert(*it);
    EXPECT_EQ(names, (std::set<std::string>{"density", "temperature", "vel"}));
    auto temperature = openvdb::gridPtrCast<openvdb::FloatGrid>(volume.readGrid("temperature"));
    volume.close();
    ASSERT_TRUE(temperature);
    // The source emits at 600 K into 293 K surroundings: the hottest voxel lies in between and
    // well above ambient (Shepard-normalised rasterisation cannot exceed the hottest particle).
    float hottest = 0;
    for (auto it = temperature->cbeginValueOn(); it; ++it) hottest = std::max(hottest, *it);
    std::printf("[measured] hottest temperature voxel %.1f K\n", hottest);
    EXPECT_GT(hottest, 400.f);
    EXPECT_LE(hottest, 600.5f);
    // Outside the plume the grid reads the scene's ambient temperature (the default 293.15 K),
    // which its metadata also gives.
    EXPECT_EQ(temperature->background(), 293.15f);
    EXPECT_EQ(temperature->metaValue<float>("ghostfx_ambient_temperature"), 293.15f);
    EXPECT_EQ(temperature->tree().getValue(openvdb::Coord(100000, 100000, 100000)), 293.15f);
    EXPECT_FALSE(fs::exists(out / "liquid.0001.vdb")) << "no liquid output in a gas scene";
    EXPECT_GT(pointCount(out / "gas_points.0003.vdb"), 0u);

    // The gas run resumes like the liquid one.
    const Result resumed =
        run("run " + path + " --out " + (mDir / "b").string() + " -q --frames 1-3 --resume "
            + (out / "checkpoint.0002.h5").string());
    ASSERT_EQ(resumed.code, 0) << resumed.err;
    EXPECT_EQ(
        checkpointDifference(path, out / "checkpoint.0003.h5", mDir / "b" / "checkpoint.0003.h5"),
        "");

    // The ambient-air baseline needs the box it fills with air.
    Json noBox = plumeScene();
    noBox.erase("domain");
    noBox["settings"]["method"] = "gas_ambient";
    EXPECT_CONTAINS(errorLine("run " + write(noBox, "nobox.json") + " --out " + out.string()),
                    "settings.method = \"gas_ambient\": the ambient-air baseline fills a box with "
                    "air: expected domain.kill_box");
}

TEST_F(Cli, AttractorRunsAndACheckpointWithoutItIsRefused)
{
    // [RYY15] Fig. 7: the plume's source with an attractor above it. A checkpoint written
    // without the attractor must not resume the scene with it (force_fields are part of the
    // simulation fingerprint), and the message names the difference.
    const std::string path = write(plumeScene(), "plume.json");
    const fs::path out = mDir / "out";
    ASSERT_EQ(run("run " + path + " --out " + out.string() + " -q --frames 1-2").code, 0);
    const std::string field = " -D "
                              "'force_fields=[{\"name\":\"magic\",\"attractor\":{\"position\":[0.3,"
                              "0.6,0],\"strength\":2}}]'";
    const std::string line = errorLine("run " + path + field + " --out " + (mDir / "b").string()
                                       + " --resume " + (out / "checkpoint.0002.h5").string());
    EXPECT_CONTAINS(
        line,
        "checkpoint.0002.h5' was written with different settings: /force_fields is missing "
        "there, [{\"attractor\":{\"position\":[0.3,0.6,0],\"strength\":2},\"name\":\"magic\"}] "
        "in this scene");
    // The scene with the attractor runs, and says so.
    const Result r = run("run " + path + field + " --out " + (mDir / "c").string()
                         + " --progress log --frames 1-2");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_CONTAINS(r.err, "gas + 1 attractor, spacing 0.04 m");
    // And a liquid scene refuses it.
    EXPECT_CONTAINS(
        errorLine("run " + write(smallScene()) + field + " --out " + (mDir / "d").string()),
        "force_fields: attractors act on gas; this scene has no gas");
}

TEST_F(Cli, BoilingPanRunsLiquidAndVapour)
{
    const Json scene = ghostfx::testing::boilingPanScene(5, 2);
    const fs::path out = mDir / "out";
    const Result r =
        run("run " + write(scene, "pan.json") + " --out " + out.string() + " --progress log");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(out / "liquid.0002.vdb"));
    ASSERT_TRUE(fs::exists(out / "gas.0002.vdb"));
    const std::size_t vapour = pointCount(out / "gas_points.0002.vdb");
    std::printf("[measured] %zu vapour particles after 2 frames\n", vapour);
    EXPECT_GT(vapour, 0u);
    // The vapour's temperature grid reads the gas's ambient temperature outside the vapour.
    openvdb::io::File gas((out / "gas.0002.vdb").string());
    gas.open();
    auto vapourTemperature =
        openvdb::gridPtrCast<openvdb::FloatGrid>(gas.readGrid("temperature"));
    gas.close();
    ASSERT_TRUE(vapourTemperature);
    EXPECT_EQ(vapourTemperature->background(), 293.15f);
    EXPECT_EQ(vapourTemperature->metaValue<float>("ghostfx_ambient_temperature"), 293.15f);
    // Mass budget per step in the statistics: liquid + gas stays constant (float round-off).
    const std::string csv = slurp(out / "stats.csv");
    EXPECT_NE(csv.find("mass_liquid"), std::string::npos);
}

TEST_F(Cli, AnimatedSolidsFollowKeysAndFileSequences)
{
    // A ball solid from a per-frame file sequence: frame 1 at x = 0.1, frame 2 at x = 0.2.
    for (int f = 1; f <= 2; ++f) {
        auto ball =
            sph::makeSphereLevelSet(sph::Vec3(0.1f * float(f), 0.2f, 0.15f), 0.04f, 0.0075f);
        ball->setName("ball");
        char name[64];
        std::snprintf(name, sizeof(name), "ball.%04d.vdb", f);
        openvdb::io::File((mDir / name).string()).write(openvdb::GridPtrVec{ball});
    }
    auto first = sph::makeSphereLevelSet(sph::Vec3(0.1f, 0.2f, 0.15f), 0.04f, 0.0075f);
    first->setName("ball");
    openvdb::io::File((mDir / "ball.vdb").string()).write(openvdb::GridPtrVec{first});
    Json scene = smallScene();
    scene["settings"]["frame_range"] = {1, 2};
    scene["solids"].push_back(
        Json::parse(R"({ "name": "ball", "geometry": { "file": "ball.vdb", "grid": "ball" },
                                              "sequence": { "file": "ball.$F4.vdb", "grid": "ball" } })"));
    // A paddle keyed to slide 0.05 m in x over the first frame.
    scene["solids"].push_back(Json::parse(R"({ "name": "paddle",
        "geometry": { "box": { "min": [0.2, 0.0, 0.0], "max": [0.23, 0.1, 0.3] } },
        "motion": { "keys": [ { "time": 0, "translate": [0, 0, 0] }, { "time": 0.0333333333, "translate": [-0.05, 0, 0] } ] } })"));
    const std::string path = write(scene);
    const fs::path out = mDir / "out";
    const Result r =
        run("run " + path + " --out " + out.string() + " -q -D outputs.checkpoint.every=1");
    ASSERT_EQ(r.code, 0) << r.err;

    // Ghosts of solid 1 (the ball) sit around its frame-2 centre; those of solid 2 (the paddle)
    // moved with it by -0.05 m.
    const std::string fingerprint = vdbio::readScene(path).simulationFingerprint();
    const sph::SolverState state =
        vdbio::readCheckpoint((out / "checkpoint.0002.h5").string(), fingerprint);
    const auto& index = state.particles.scalarChannel("solid_index");
    double ballX = 0, paddleMinX = 1e9;
    std::size_t ballCount = 0;
    for (std::size_t i = 0; i < state.particles.size(); ++i) {
        if (state.particles.kinds()[i] != sph::ParticleKind::GhostSolid) continue;
        if (index[i] == 1.f) {
            ballX += state.particles.positions()[i][0];
            ++ballCount;
        } else if (index[i] == 2.f) {
            paddleMinX = std::min(paddleMinX, double(state.particles.positions()[i][0]));
        }
    }
    ASSERT_GT(ballCount, 0u);
    ballX /= double(ballCount);
    std::printf("[measured] ball ghosts centred at x = %.4f m (file of frame 2: 0.2), paddle min x "
                "= %.4f m\n",
                ballX, paddleMinX);
    // The ghost layer is sampled symmetrically around the ball: its mean is the centre to a
    // fraction of a spacing (0.015 m).
    EXPECT_NEAR(ballX, 0.2, 0.005);
    // Keyed motion: held at the last key after t = 1/30 s, so the paddle's left face is at 0.15 m.
    EXPECT_NEAR(paddleMinX, 0.15, 0.002);

    // A missing frame of the sequence is a clear error naming the file.
    const std::string line = errorLine("run " + path + " --out " + out.string() + " --frames 1-3");
    EXPECT_CONTAINS(line, "solids[1].sequence: file '" + (mDir / "ball.0003.vdb").string()
                              + "' does not exist");
}

/// Sets an environment variable (or unsets it, for null) for one scope.
class ScopedEnv
{
public:
    ScopedEnv(const char* name, const char* value) : mName(name)
    {
        if (const char* old = std::getenv(name)) mOld = old;
        if (value) ::setenv(name, value, 1);
        else ::unsetenv(name);
    }
    ~ScopedEnv()
    {
        if (mOld) ::setenv(mName.c_str(), mOld->c_str(), 1);
        else ::unsetenv(mName.c_str());
    }

private:
    std::string mName;
    std::optional<std::string> mOld;
};

TEST_F(Cli, SampleCacheIsPerUserByDefault)
{
    // With neither --sample-cache nor $GHOSTFX_SAMPLE_CACHE, runs share the per-user folder
    // $XDG_CACHE_HOME/ghostfx/samples (as SPlisHSPlasH keeps its volume maps): a scene run
    // again loads its shapes. "off" in either place runs without one.
    const std::string path = write(smallScene());
    const fs::path xdg = mDir / "xdg", folder = xdg / "ghostfx" / "samples";
    ScopedEnv noFolder("GHOSTFX_SAMPLE_CACHE", nullptr);
    ScopedEnv cacheHome("XDG_CACHE_HOME", xdg.string().c_str());
    const std::string args = "run " + path + " --frames 1-1 --progress log --out ";
    const Result first = run(args + (mDir / "a").string());
    ASSERT_EQ(first.code, 0) << first.err;
    EXPECT_CONTAINS(first.err,
                    "sample cache '" + folder.string() + "': 0 shapes loaded, 2 sampled");
    const Result second = run(args + (mDir / "b").string());
    ASSERT_EQ(second.code, 0) << second.err;
    EXPECT_CONTAINS(second.err, "2 shapes loaded, 0 sampled and kept");
    EXPECT_EQ(gridBytes(mDir / "a" / "liquid_points.0001.vdb"),
              gridBytes(mDir / "b" / "liquid_points.0001.vdb"));
    {
        const Result off = run(args + (mDir / "c").string() + " --sample-cache off");
        ASSERT_EQ(off.code, 0) << off.err;
        EXPECT_EQ(off.err.find("sample cache"), std::string::npos) << off.err;
        ScopedEnv envOff("GHOSTFX_SAMPLE_CACHE", "off");
        const Result alsoOff = run(args + (mDir / "d").string());
        ASSERT_EQ(alsoOff.code, 0) << alsoOff.err;
        EXPECT_EQ(alsoOff.err.find("sample cache"), std::string::npos) << alsoOff.err;
    }
    // The folder is kept within $GHOSTFX_SAMPLE_CACHE_LIMIT_MB: a bad value is one clear line.
    {
        ScopedEnv limit("GHOSTFX_SAMPLE_CACHE_LIMIT_MB", "lots");
        EXPECT_CONTAINS(errorLine(args + (mDir / "e").string()),
                        "GHOSTFX_SAMPLE_CACHE_LIMIT_MB = 'lots': expected a whole number of MiB");
        EXPECT_FALSE(fs::exists(mDir / "e" / "liquid_points.0001.vdb"));
    }
    // A default folder that cannot be made is not the user's doing: a warning, and the run
    // goes on without a cache (a folder the user names is an error, see the test below).
    std::ofstream(mDir / "file") << "not a folder";
    ScopedEnv badHome("XDG_CACHE_HOME", (mDir / "file").string().c_str());
    const Result unwritable = run(args + (mDir / "f").string());
    ASSERT_EQ(unwritable.code, 0) << unwritable.err;
    EXPECT_CONTAINS(unwritable.err, "ghostfx: warning: sample cache folder '"
                                        + (mDir / "file" / "ghostfx" / "samples").string());
    EXPECT_CONTAINS(unwritable.err, "running without a sample cache");
    EXPECT_TRUE(fs::exists(mDir / "f" / "liquid_points.0001.vdb"));
}

TEST_F(Cli, SampleCacheGivesTheSameRunWithoutSamplingAgain)
{
    // `--sample-cache DIR` (or $GHOSTFX_SAMPLE_CACHE): the first run samples the tank and the
    // water and keeps them, the second loads both; the frame files are the same grid for grid.
    const std::string path = write(smallScene());
    const fs::path cache = mDir / "cache", a = mDir / "a", b = mDir / "b";
    const Result first = run("run " + path + " --frames 1-2 --progress log --out " + a.string()
                             + " --sample-cache " + cache.string());
    ASSERT_EQ(first.code, 0) << first.err;
    EXPECT_CONTAINS(first.err, "0 shapes loaded, 2 sampled and kept");
    const Result second = run("run " + path + " --frames 1-2 --progress log --out " + b.string()
                              + " --sample-cache " + cache.string());
    ASSERT_EQ(second.code, 0) << second.err;
    EXPECT_CONTAINS(second.err, "2 shapes loaded, 0 sampled and kept");
    EXPECT_EQ(gridBytes(a / "liquid_points.0002.vdb"), gridBytes(b / "liquid_points.0002.vdb"));
    // The environment variable does the same.
    ::setenv("GHOSTFX_SAMPLE_CACHE", cache.string().c_str(), 1);
    const Result third =
        run("run " + path + " --frames 1-1 --progress log --out " + (mDir / "c").string());
    ::setenv("GHOSTFX_SAMPLE_CACHE", "off", 1); // as tests/main.cc left it
    EXPECT_EQ(third.code, 0) << third.err;
    EXPECT_CONTAINS(third.err, "2 shapes loaded, 0 sampled and kept");

    // A cache folder that cannot be made: one clear line naming it.
    std::ofstream(mDir / "file") << "not a folder";
    const std::string line =
        errorLine("run " + path + " --sample-cache " + (mDir / "file" / "cache").string());
    EXPECT_CONTAINS(line, "sample cache folder '" + (mDir / "file" / "cache").string() + "'");
}
