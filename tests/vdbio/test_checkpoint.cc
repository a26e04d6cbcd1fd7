/// @file   test_checkpoint.cc
/// @brief  HDF5 checkpoints (bit-exact round trip, header, refusals with their messages), a run
///         resumed from a checkpoint continuing bit for bit (Ghost and Basic SPH), and the
///         per-step statistics files (HDF5 + CSV, resume truncation).
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/Stats.h>

#include "common/ResumeScene.h"
#include "common/StateDiff.h"

#include "common/Expect.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;
using namespace ghostfx::vdbio;

namespace {

using ghostfx::testing::freshDir;

constexpr Real H = Real(0.01);

using ghostfx::testing::firstDifference;
using ghostfx::testing::sameBytes;

/// A particle set with awkward values: every kind, ids with gaps, named channels with
/// non-zero defaults, and reals that only a bit-exact store keeps (denormals, -0, NaN, inf).
SolverState awkwardState()
{
    SolverState state;
    state.solver = "ghost";
    ParticleSet& p = state.particles;
    const Real tiny = std::numeric_limits<Real>::denorm_min();
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    const Real inf = std::numeric_limits<Real>::infinity();
    for (int i = 0; i < 40; ++i) {
        const Real t = Real(0.1) * Real(i) + Real(1) / Real(3);
        p.add(Vec3(t, -t * t, std::sqrt(t)), Vec3(Real(1e-7) * t, Real(-0.0), Real(1e30) / (t + 1)),
              Real(0.001) * t, ParticleKind(i % 5));
    }
    p.positions()[3] = Vec3(tiny, -tiny, Real(-0.0));
    p.velocities()[4] = Vec3(nan, inf, -inf);
    p.densities()[5] = std::numeric_limits<Real>::max();
    p.pressures()[6] = std::numeric_limits<Real>::lowest();
    auto& weight = p.addScalarChannel("air_weight", Real(1));
    auto& normal = p.addVectorChannel("normal", Vec3(0, 1, 0));
    p.addScalarChannel("solid_index", Real(-1));
    for (std::size_t i = 0; i < p.size(); ++i) {
        weight[i] = Real(1) / Real(i + 7);
        normal[i] = Vec3(Real(i), Real(1) / Real(i + 1), Real(-3));
    }
    // Gaps in the ids: remove every third particle, then add two more.
    std::vector<std::uint8_t> remove(p.size(), 0);
    for (std::size_t i = 0; i < remove.size(); i += 3) remove[i] = 1;
    p.removeIf(remove);
    p.add(Vec3(Real(0.5)), Vec3(0), Real(0.002), ParticleKind::Liquid);
    p.add(Vec3(Real(0.25)), Vec3(0), Real(0.002), ParticleKind::GhostAir);
    p.setNextId(1000);

    state.reals["time"] = 0.1 + 0.2;
    state.reals["tiny"] = std::numeric_limits<double>::denorm_min();
    state.reals["negative_zero"] = -0.0;
    state.reals["not_a_number"] = std::numeric_limits<double>::quiet_NaN();
    state.integers["step"] = 123456789012345LL;
    state.integers["lowest"] = std::numeric_limits<std::int64_t>::min();
    state.integers["highest"] = std::numeric_limits<std::int64_t>::max();
    return state;
}

const char* SETTINGS = R"({"version": 1, "settings": {"method": "ghost", "stiffness": 2000,
    "spacing": 0.01, "gravity": [0, -9.81, 0]}, "solids": [{"file": "tank.vdb"}]})";

std::string messageOf(const std::function<void()>& fn)
{
    try {
        fn();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "(no exception)";
}

/// The message of reading the checkpoint `path` for `settings`, which must throw E; printed as
/// "[measured] <what> refusal: ...".
template <typename E>
std::string readRefusal(const char* what, const std::string& path, const std::string& settings)
{
    const std::string message =
        ghostfx::testing::errorOf<E>([&] { readCheckpoint(path, settings); });
    std::printf("[measured] %s refusal: %s\n", what, message.c_str());
    return message;
}

} // namespace

// Checkpoint files ----------------------------------------------------------------------------

TEST(Checkpoint, ParticleSetWithNamedChannelsRoundTripsBitExactly)
{
    const fs::path dir = freshDir("roundtrip");
    const std::string path = (dir / "state.h5").string();
    const SolverState state = awkwardState();
    writeCheckpoint(path, state, SETTINGS, 7);
    const SolverState back = readCheckpoint(path, SETTINGS);
    const std::string difference = firstDifference(state, back);
    std::printf("[measured] checkpoint round trip: %zu particles, %zu + %zu named channels, "
                "%zu bytes on disk, Real = %zu bytes, first difference '%s'\n",
                back.particles.size(), back.particles.scalarChannelNames().size(),
                back.particles.vectorChannelNames().size(), std::size_t(fs::file_size(path)),
                sizeof(Real), difference.c_str());
    // Exact: stored in the build's own float type, so nothing is converted.
    EXPECT_EQ(difference, "");
    EXPECT_EQ(back.particles.nextId(), 1000);
    // Only the checkpoint is left in the folder (the temporary was renamed).
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);

    // An empty set round-trips too.
    SolverState empty;
    empty.solver = "basic";
    empty.particles.addVectorChannel("vstar");
    writeCheckpoint(path, empty, "{}", 0);
    EXPECT_EQ(firstDifference(empty, readCheckpoint(path, "{}")), "");
    fs::remove_all(dir);
}

TEST(Checkpoint, HeaderFields)
{
    const fs::path dir = freshDir("header");
    const std::string path = (dir / "state.h5").string();
    const SolverState state = awkwardState();
    writeCheckpoint(path, state, SETTINGS, 7);
    const CheckpointHeader header = readCheckpointHeader(path);
    EXPECT_EQ(header.schemaVersion, CHECKPOINT_SCHEMA_VERSION);
    EXPECT_EQ(header.solver, "ghost");
    EXPECT_EQ(header.settings, SETTINGS);
    EXPECT_EQ(header.frame, 7);
    EXPECT_EQ(header.time, 0.1 + 0.2);
    EXPECT_EQ(header.step, 123456789012345LL);
    std::size_t total = 0;
    for (int k = 0; k < 5; ++k) {
        const std::string kind = kindName(ParticleKind(k));
        ASSERT_EQ(header.countPerKind.count(kind), 1u) << kind;
        EXPECT_EQ(header.countPerKind.at(kind), state.particles.count(ParticleKind(k))) << kind;
        total += header.countPerKind.at(kind);
    }
    EXPECT_EQ(total, state.particles.size());
    fs::remove_all(dir);
}

TEST(Checkpoint, SeveralStatesRoundTripInOrder)
{
    // A boiling scene's checkpoint: the liquid, its vapour and the phase transition (a state
    // with no particles), each read back bit for bit and in order.
    const fs::path dir = freshDir("states");
    const std::string path = (dir / "boiling.h5").string();
    SolverState gas = awkwardState();
    gas.solver = "gas";
    gas.particles.addScalarChannel("h", Real(0.03));
    SolverState phase;
    phase.solver = "phase_transition";
    phase.integers["boiled"] = 12;
    phase.reals["vapour_mass"] = 0.1 + 0.2;
    const std::vector<SolverState> states = {awkwardState(), gas, phase};
    writeCheckpoint(path, states, SETTINGS, 3);
    EXPECT_EQ(readCheckpointHeader(path).stateCount, 3);
    const std::vector<SolverState> back = readCheckpointStates(path, SETTINGS);
    ASSERT_EQ(back.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(firstDifference(states[k], back[k]), "") << k;
    // The one-state reader refuses it rather than drop two states.
    EXPECT_EQ(readRefusal<IoError>("several", path, SETTINGS),
              "checkpoint '" + path
                  + "': holds 3 solver states (a boiling scene's), expected one");
    // A damaged count is refused with its value.
    vdbio::detail::patchCheckpointAttribute(path, "state_count", std::int64_t(5));
    EXPECT_EQ(ghostfx::testing::errorOf<IoError>([&] { readCheckpointStates(path, SETTINGS); }),
              "checkpoint '" + path + "': missing group '/state_3'");
    fs::remove_all(dir);
}

TEST(Checkpoint, AttachmentsRoundTripBesideTheStates)
{
    // Byte strings a caller keeps beside the states (the Python module's added shapes): read
    // back byte for byte, NULs and high bytes included; a checkpoint without them has none,
    // and its states read the same.
    const fs::path dir = freshDir("attachments");
    const std::string with = (dir / "with.h5").string(), without = (dir / "without.h5").string();
    const std::string bytes("\0\x01\xff vdb", 7);
    const CheckpointAttachments attachments = {{"a.json", "{\"x\": 1}"}, {"b.vdb", bytes},
                                               {"empty", ""}};
    writeCheckpoint(with, {awkwardState()}, SETTINGS, 2, attachments);
    writeCheckpoint(without, {awkwardState()}, SETTINGS, 2);
    EXPECT_EQ(readCheckpointAttachments(with), attachments);
    EXPECT_TRUE(readCheckpointAttachments(without).empty());
    EXPECT_EQ(firstDifference(readCheckpoint(with, SETTINGS), awkwardState()), "");
    fs::remove_all(dir);
}

TEST(Checkpoint, RefusesOtherSchemaAndPrecision)
{
    const fs::path dir = freshDir("schema");
    const std::string path = (dir / "x.h5").string();
    writeCheckpoint(path, awkwardState(), SETTINGS, 1);
    vdbio::detail::patchCheckpointAttribute(path, "schema_version", std::int64_t(3));
    EXPECT_EQ(readCheckpointHeader(path).schemaVersion, 3); // reported, not refused
    EXPECT_EQ(readRefusal<IoError>("schema", path, SETTINGS),
              "checkpoint '" + path + "': schema version 3, this ghostfx reads 1 to 2");

    // Schema 1 is schema 2 with one state and no state count: read as that, a liquid state
    // given the keys its solver added since at the values such states were saved with.
    SolverState old = awkwardState();
    old.integers["emitters"] = 2;
    old.integers.erase("air_phase");
    writeCheckpoint(path, old, SETTINGS, 1);
    vdbio::detail::patchCheckpointAttribute(path, "schema_version", std::int64_t(1));
    vdbio::detail::patchCheckpointAttribute(path, "state_count", std::int64_t(7));
    EXPECT_EQ(readCheckpointHeader(path).stateCount, 1);
    const SolverState migrated = readCheckpoint(path, SETTINGS);
    SolverState expected = old;
    expected.integers["pressure_dfsph"] = 0;
    expected.integers["air_weights_complete"] = 0;
    expected.integers["air_phase"] = std::max<std::int64_t>(1, old.integers.at("step"));
    expected.reals["air_phase_credit"] = 0;
    for (const char* e : {"0", "1"}) {
        expected.reals[std::string("emitter_credit_") + e] = 0;
        expected.reals[std::string("emitter_fill_scale_") + e] = 1;
    }
    EXPECT_EQ(firstDifference(expected, migrated), "");

    // Written by a build of the other precision (float vs double).
    writeCheckpoint(path, awkwardState(), SETTINGS, 1);
    const std::string other = sizeof(Real) == 4 ? "double" : "float";
    vdbio::detail::patchCheckpointAttribute(path, "real", other);
    const std::string precision = readRefusal<IoError>("precision", path, SETTINGS);
    EXPECT_NE(precision.find("checkpoint '" + path + "': written by a build with Real = " + other),
              std::string::npos)
        << precision;
    fs::remove_all(dir);
}

TEST(Checkpoint, RefusesDifferentSettingsNamingTheKeyAndBothValues)
{
    const fs::path dir = freshDir("settings");
    const std::string path = (dir / "c.h5").string();
    writeCheckpoint(path, awkwardState(), SETTINGS, 1);

    std::string here = SETTINGS;
    here.replace(here.find("2000"), 4, "5000");
    EXPECT_EQ(readRefusal<SceneError>("settings", path, here),
              "checkpoint '" + path
                  + "' was written with different settings: "
                    "/settings/stiffness is 2000 there, 5000 in this scene");

    // A key only one side has, and a difference inside an array.
    EXPECT_EQ(firstSettingsDifference(R"({"a": {"b": 1}})", R"({"a": {"b": 1, "c": "x"}})"),
              R"(/a/c is missing there, "x" in this scene)");
    EXPECT_EQ(firstSettingsDifference(R"({"a": {"b": 1, "c": true}})", R"({"a": {"b": 1}})"),
              "/a/c is true there, missing in this scene");
    EXPECT_EQ(firstSettingsDifference(R"({"g": [0, -9.81, 0]})", R"({"g": [0, -9.8, 0]})"),
              "/g/1 is -9.81 there, -9.8 in this scene");
    EXPECT_EQ(firstSettingsDifference(R"({"a/b": 1})", R"({"a/b": 2})"),
              "/a~1b is 1 there, 2 in this scene");
    // The same values written differently are the same settings.
    EXPECT_EQ(firstSettingsDifference(R"({"k": 2000, "s": 0.5})", R"({"s": 0.50, "k": 2000.0})"),
              "");
    EXPECT_NO_THROW(readCheckpoint(path, std::string(SETTINGS) + "  \n"));
    EXPECT_THROW(readCheckpoint(path, "{not json"), ValueError);
    fs::remove_all(dir);
}

TEST(Checkpoint, RefusesMissingNonHdf5AndForeignFiles)
{
    const fs::path dir = freshDir("refuse");
    const std::string missing = (dir / "missing.h5").string();
    EXPECT_EQ(readRefusal<IoError>("missing file", missing, SETTINGS),
              "checkpoint '" + missing + "': no such file");
    EXPECT_THROW(readCheckpointHeader(missing), IoError);

    const std::string text = (dir / "notes.h5").string();
    std::ofstream(text) << "this is not an HDF5 file\n";
    EXPECT_EQ(readRefusal<IoError>("non-HDF5 file", text, SETTINGS),
              "checkpoint '" + text + "': not an HDF5 file, so not a ghostfx checkpoint");

    // An HDF5 file that is not a checkpoint: a statistics file.
    const std::string stats = (dir / "stats.h5").string();
    StatsWriter writer(stats, (dir / "stats.csv").string());
    writer.append({{{"step", 1}, {"time", 0.01}}});
    writer.flush();
    const std::string foreign = readRefusal<IoError>("foreign HDF5 file", stats, SETTINGS);
    EXPECT_NE(foreign.find("checkpoint '" + stats + "': not a ghostfx checkpoint"),
              std::string::npos)
        << foreign;

    // Writing into a folder that does not exist fails with the file's name.
    const std::string nowhere = (dir / "no" / "such" / "c.h5").string();
    const std::string writeMessage =
        messageOf([&] { writeCheckpoint(nowhere, awkwardState(), SETTINGS, 0); });
    EXPECT_NE(writeMessage.find("checkpoint '" + nowhere + "': cannot write it"), std::string::npos)
        << writeMessage;
    fs::remove_all(dir);
}

// Resume from a checkpoint ------------------------------------------------------------------------

namespace {

/// The shared scene (tests/common/ResumeScene.h), described as a caller (the CLI) would
/// describe its effective settings for the checkpoint's fingerprint.
struct ResumeScene : ghostfx::testing::ResumeScene
{
    ResumeScene(Method method, int substeps, const Vec3& floorVelocity)
        : ghostfx::testing::ResumeScene(method, substeps, floorVelocity, 11)
    {}

    std::string settingsJson() const
    {
        std::ostringstream os;
        os << R"({"settings": {"method": ")" << methodName(settings.method) << R"(", "substeps": )"
           << settings.substeps << R"(, "seed": )" << settings.seed << "}}";
        return os.str();
    }
};

/// Run `frames` frames uninterrupted and `split` + checkpoint + resume; compare bit for bit.
void checkResume(const ResumeScene& scene, int frames, int split, const std::string& tag)
{
    const auto t0 = std::chrono::steady_clock::now();
    GhostSolver whole(scene.settings);
    scene.start(whole, frames);

    const fs::path dir = freshDir("resume_" + tag);
    const std::string path = (dir / "checkpoint.h5").string();
    {
        GhostSolver first(scene.settings);
        scene.start(first, split);
        writeCheckpoint(path, first.saveState(), scene.settingsJson(), first.frame());
    } // the first solver is gone: nothing survives but the file

    const CheckpointHeader header = readCheckpointHeader(path);
    EXPECT_EQ(header.frame, split);
    GhostSolver resumed(scene.settings);
    resumed.restoreState(readCheckpoint(path, scene.settingsJson()));
    const std::size_t restoredSolid =
        resumed.count(ParticleKind::GhostSolid) + resumed.count(ParticleKind::Boundary);
    scene.addInputs(resumed); // same solids and emitters; no liquid
    EXPECT_EQ(resumed.count(ParticleKind::GhostSolid) + resumed.count(ParticleKind::Boundary),
              restoredSolid); // not sampled again
    EXPECT_EQ(resumed.frame(), split);
    while (resumed.frame() < frames) resumed.advanceFrame();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const SolverState a = whole.saveState(), b = resumed.saveState();
    const std::string difference = firstDifference(a, b);
    std::printf(
        "[measured] %s resume: %d frames vs %d + checkpoint (%zu bytes) + %d: %zu particles "
        "(%zu liquid, %zu ghost air, %zu ghost solid, %zu boundary), %llu steps, "
        "emitted %zu, killed %zu; first difference '%s'; %.1f s\n",
        tag.c_str(), frames, split, std::size_t(fs::file_size(path)), frames - split,
        a.particles.size(), whole.count(ParticleKind::Liquid), whole.count(ParticleKind::GhostAir),
        whole.count(ParticleKind::GhostSolid), whole.count(ParticleKind::Boundary),
        static_cast<unsigned long long>(whole.stepCount()), whole.emittedCount(),
        whole.killedCount(), difference.c_str(), seconds);
    // Exact: the resumed solver performs the same operations on the same bits (STYLE.md rule 6:
    // results do not depend on thread timing), so any difference is state the checkpoint lost.
    EXPECT_EQ(difference, "");
    EXPECT_TRUE(sameBytes(a.particles.positions(), b.particles.positions()));
    EXPECT_TRUE(sameBytes(a.particles.velocities(), b.particles.velocities()));
    EXPECT_TRUE(sameBytes(a.particles.ids(), b.particles.ids()));
    EXPECT_EQ(whole.time(), resumed.time());
    EXPECT_EQ(whole.stepCount(), resumed.stepCount());
    EXPECT_EQ(whole.emittedCount(), resumed.emittedCount());
    EXPECT_EQ(whole.killedCount(), resumed.killedCount());
    // The scene exercises what it should.
    EXPECT_GT(whole.emittedCount(), 0u);
    EXPECT_GT(whole.killedCount(), 0u);
    fs::remove_all(dir);
}

} // namespace

TEST(Resume, GhostFromCheckpointIsBitIdentical)
{
    // 12 fixed substeps a frame (the checkpoint, at step 24, falls in an air fade; the
    // CFL-adaptive path is covered by the Basic run below and by
    // tests/ghost/test_resume.cc). The floor slides at 5 cm/s, so its ghosts move with it.
    checkResume(ResumeScene(Method::Ghost, 12, Vec3(Real(0.05), 0, 0)), 4, 2, "ghost");
}

TEST(Resume, BasicFromCheckpointIsBitIdentical)
{
    // CFL-adaptive steps: the saved max acceleration decides every dt after the resume, and the
    // Lennard-Jones strength chosen at the first step must come back. Basic SPH's stiff
    // Lennard-Jones walls need the acceleration limit of the adaptive step (with fixed steps
    // of 1/600 s this scene blows up in frame 3, as tests/ghost/test_extremes.cc describes).
    // Seed 12: with seed 11 (the Ghost scenes' seed) the emitted jet skims the moving floor and
    // takes a Lennard-Jones kick at its edge in frame 3 (1 of 12 seeds tried, Basic SPH's known
    // fragility); this test is about resuming, not about Basic SPH's stability.
    ResumeScene scene(Method::Basic, 0, Vec3(Real(0.05), 0, 0));
    scene.settings.seed = 12;
    checkResume(scene, 4, 2, "basic");
}

// Statistics --------------------------------------------------------------------------------------

namespace {

std::vector<std::string> lines(const std::string& path)
{
    std::ifstream in(path);
    std::vector<std::string> out;
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
}

StatsRow row(std::int64_t step, double time)
{
    return StatsRow{{{"frame", double(step / 4)},
                     {"step", double(step)},
                     {"time", time},
                     {"dt", 0.1},
                     {"count_liquid", 1000.0 + double(step)},
                     {"max_speed", 1.0 / 3.0},
                     {"bytes_per_particle", 84}}};
}

} // namespace

TEST(Stats, AppendFlushAndReadBack)
{
    const fs::path dir = freshDir("stats");
    const std::string h5 = (dir / "stats.h5").string(), csv = (dir / "stats.csv").string();
    StatsWriter writer(h5, csv);
    writer.flush(); // nothing yet: no files
    EXPECT_FALSE(fs::exists(h5));
    for (int s = 1; s <= 6; ++s) writer.append(row(s, 0.1 * s));
    writer.flush();
    EXPECT_EQ(writer.rows(), 6u);

    const StatsTable table = readStats(h5);
    const std::vector<std::string> columns{
        "frame", "step", "time", "dt", "count_liquid", "max_speed", "bytes_per_particle"};
    EXPECT_EQ(table.columns, columns);
    ASSERT_EQ(table.rows.size(), 6u);
    EXPECT_EQ(table.rows[2][2], 0.1 * 3); // doubles stored as doubles: exact
    EXPECT_EQ(table.rows[5][5], 1.0 / 3.0);
    EXPECT_EQ(table.rows[5][1], 6.0);

    const auto text = lines(csv);
    std::printf("[measured] stats: %zu rows, csv header '%s', row 3 '%s'\n", table.rows.size(),
                text.at(0).c_str(), text.at(3).c_str());
    ASSERT_EQ(text.size(), 7u);
    EXPECT_EQ(text[0], "frame,step,time,dt,count_liquid,max_speed,bytes_per_particle");
    // Shortest text that reads back to the same double.
    EXPECT_EQ(text[3], "0,3,0.30000000000000004,0.1,1003,0.3333333333333333,84");
    EXPECT_EQ(std::stod("0.30000000000000004"), 0.1 * 3);
    EXPECT_EQ(statsUnit("time"), "s");
    EXPECT_EQ(statsUnit("t_pressure"), "s");
    EXPECT_EQ(statsUnit("max_speed"), "m/s");
    EXPECT_EQ(statsUnit("bytes_per_particle"), "bytes");

    // A row with other columns is refused, naming the column.
    StatsRow bad = row(7, 0.7);
    bad.values[3].first = "substep";
    const std::string message = messageOf([&] { writer.append(bad); });
    EXPECT_NE(message.find("column 3 is 'substep', expected 'dt'"), std::string::npos) << message;
    EXPECT_THROW(writer.append(StatsRow{{{"frame", 0}}}), ValueError);
    EXPECT_THROW(StatsWriter(h5, csv).append(StatsRow{{{"a/b", 0}}}), ValueError);
    EXPECT_EQ(writer.rows(), 6u);
    fs::remove_all(dir);
}

TEST(Stats, ResumeFromKeepsRowsUpToTheCheckpointStep)
{
    const fs::path dir = freshDir("stats_resume");
    const std::string h5 = (dir / "stats.h5").string(), csv = (dir / "stats.csv").string();
    {
        StatsWriter writer(h5, csv);
        for (int s = 1; s <= 10; ++s) writer.append(row(s, 0.1 * s));
        writer.flush();
    }
    // The run was checkpointed at step 6 and killed at step 10: resume from 6.
    StatsWriter resumed(h5, csv);
    resumed.resumeFrom(6);
    EXPECT_EQ(resumed.rows(), 6u);
    for (int s = 7; s <= 8; ++s) resumed.append(row(s, 0.1 * s + 1e-3));
    resumed.flush();
    const StatsTable table = readStats(h5);
    ASSERT_EQ(table.rows.size(), 8u);
    for (int r = 0; r < 8; ++r) EXPECT_EQ(table.rows[r][1], double(r + 1));
    EXPECT_EQ(table.rows[6][2], 0.1 * 7 + 1e-3); // the new row, not the old one
    EXPECT_EQ(lines(csv).size(), 9u);
    std::printf("[measured] stats resume: 10 rows, resumed from step 6, +2 rows -> %zu rows\n",
                table.rows.size());

    // A missing file: start empty.
    StatsWriter fresh((dir / "none.h5").string(), (dir / "none.csv").string());
    fresh.resumeFrom(6);
    EXPECT_EQ(fresh.rows(), 0u);
    fs::remove_all(dir);
}
