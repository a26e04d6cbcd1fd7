/// @file   CliHarness.h
/// @brief  What the command-line tests share: running the real `ghostfx` executable in a test's
///         own folder (captured stderr, exit code), starting it in the background to signal it,
///         reading its outputs back (point counts, grids, checkpoints, statistics columns),
///         and a boiling-pan scene more than one suite runs.
#pragma once

#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/Scene.h>

#include "common/Expect.h"
#include "common/StateDiff.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <signal.h>
#include <spawn.h>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <vector>

extern char** environ;

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace ghostfx {
namespace testing {

struct Result
{
    int code = -1; ///< exit code, or -1 for a process a signal ended
    std::string err;
};

/// A fixture whose tests run `ghostfx` in their own folder `mDir` (set by SetUp).
class CliTest : public ::testing::Test
{
protected:
    std::string write(const vdbio::Json& scene, const std::string& name = "scene.json") const
    {
        const std::string path = (mDir / name).string();
        std::ofstream(path) << scene.dump(2);
        return path;
    }

    /// Run the real executable with `args`; capture stderr.
    Result run(const std::string& args) const
    {
        const std::filesystem::path err = mDir / "stderr.txt";
        const std::string command = std::string(GHOSTFX_EXE) + " " + args + " > "
                                    + (mDir / "stdout.txt").string() + " 2> " + err.string();
        const int status = std::system(command.c_str());
        Result r;
        r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        r.err = slurp(err);
        return r;
    }

    /// An error run: exit code 1 and exactly one line on stderr, which is returned.
    std::string errorLine(const std::string& args) const
    {
        const Result r = run(args);
        EXPECT_EQ(r.code, 1) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1)
            << "expected one line: " << r.err;
        EXPECT_EQ(r.err.rfind("ghostfx: error: ", 0), 0u) << r.err;
        return r.err;
    }

    /// Start `ghostfx args...` in the background, its stderr into `errFile`; returns its pid.
    pid_t spawn(std::vector<std::string> args, const std::filesystem::path& errFile) const
    {
        args.insert(args.begin(), GHOSTFX_EXE);
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t files;
        posix_spawn_file_actions_init(&files);
        posix_spawn_file_actions_addopen(&files, 2, errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        pid_t pid = 0;
        const int rc = posix_spawn(&pid, argv[0], &files, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&files);
        EXPECT_EQ(rc, 0);
        return pid;
    }

    std::filesystem::path mDir;
};

/// Wait (up to `limit`, looking every `poll`) until `file` exists; whether it does.
inline bool waitForFile(const std::filesystem::path& file,
                        std::chrono::seconds limit = std::chrono::seconds(120),
                        std::chrono::milliseconds poll = std::chrono::milliseconds(20))
{
    const auto start = std::chrono::steady_clock::now();
    while (!std::filesystem::exists(file)) {
        if (std::chrono::steady_clock::now() - start > limit) return false;
        std::this_thread::sleep_for(poll);
    }
    return true;
}

/// Send `signal` to the process `pid` and wait for it to end; its wait status.
inline int signalAndWait(pid_t pid, int signal)
{
    ::kill(pid, signal);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
}

/// A pan of water on a 500 K plate that boils away in about three frames (spacing 2 cm, 10
/// substeps a frame), run for frames 1 to `lastFrame`, the water's latent heat `latentHeat`
/// (J/kg, scaled for a short test).
inline vdbio::Json boilingPanScene(double latentHeat, int lastFrame)
{
    vdbio::Json scene = vdbio::Json::parse(R"({
        "ghostfx_scene": 1,
        "settings": { "method": "ghost", "spacing": 0.02, "substeps": 10 },
        "solids": [ { "name": "pan", "geometry": { "container": { "min": [0, 0, 0], "max": [0.2, 0.3, 0.2], "wall": 0.04 } } } ],
        "liquids": [ { "name": "water", "geometry": { "box": { "min": [0, 0, 0], "max": [0.2, 0.08, 0.2] } } } ],
        "heaters": [ { "name": "plate", "geometry": { "box": { "min": [-0.04, -0.04, -0.04], "max": [0.24, 0.0, 0.24] } },
                       "temperature": 500 } ],
        "phase_transition": { "initial_temperature": 372, "heating_time": 0.02 },
        "domain": { "kill_box": { "min": [-0.1, -0.1, -0.1], "max": [0.3, 1.0, 0.3] } }
    })");
    scene["settings"]["frame_range"] = {1, lastFrame};
    scene["phase_transition"]["latent_heat"] = latentHeat;
    return scene;
}

/// Points in the "particles" grid of a points file.
inline std::size_t pointCount(const std::filesystem::path& file)
{
    openvdb::io::File f(file.string());
    f.open();
    auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(f.readGrid("particles"));
    f.close();
    return grid ? std::size_t(openvdb::points::pointCount(grid->tree())) : 0;
}

/// Every grid of a .vdb file by name, as its serialised tree and metadata (a file's own header
/// carries a fresh UUID per write, so files are compared grid by grid, not byte by byte).
inline std::map<std::string, std::string> gridBytes(const std::filesystem::path& file)
{
    openvdb::io::File f(file.string());
    f.open();
    std::map<std::string, std::string> grids;
    for (auto name = f.beginName(); name != f.endName(); ++name) {
        const openvdb::GridBase::Ptr grid = f.readGrid(*name);
        std::ostringstream bytes(std::ios::binary);
        // Point grids write through the stream's metadata (attribute arrays count passes).
        auto streamMeta = std::make_shared<openvdb::io::StreamMetadata>();
        openvdb::io::setStreamMetadataPtr(bytes, streamMeta, /*transfer=*/false);
        grid->writeMeta(bytes);
        grid->writeTransform(bytes);
        grid->writeTopology(bytes);
        grid->writeBuffers(bytes);
        grids[grid->getName()] = bytes.str();
    }
    f.close();
    return grids;
}

/// "" when the checkpoints `a` and `b` of the scene file `scene` hold the same solver states
/// bit for bit, else what differs first.
inline std::string checkpointDifference(const std::string& scene, const std::filesystem::path& a,
                                        const std::filesystem::path& b)
{
    const std::string fingerprint = vdbio::readScene(scene).simulationFingerprint();
    const auto sa = vdbio::readCheckpointStates(a.string(), fingerprint);
    const auto sb = vdbio::readCheckpointStates(b.string(), fingerprint);
    if (sa.size() != sb.size()) return "the files hold different numbers of states";
    for (std::size_t k = 0; k < sa.size(); ++k) {
        const std::string d = firstDifference(sa[k], sb[k]);
        if (!d.empty()) return "state " + std::to_string(k) + ": " + d;
    }
    return "";
}

/// The values of column `name` of a stats.csv file, one per step.
inline std::vector<double> csvColumn(const std::filesystem::path& file, const std::string& name)
{
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    std::vector<std::string> header;
    std::stringstream h(line);
    for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
    const auto at = std::find(header.begin(), header.end(), name);
    EXPECT_NE(at, header.end()) << "no column '" << name << "' in " << file;
    const std::size_t column = std::size_t(at - header.begin());
    std::vector<double> values;
    while (std::getline(in, line)) {
        std::stringstream row(line);
        std::string cell;
        for (std::size_t c = 0; c <= column && std::getline(row, cell, ','); ++c) {}
        values.push_back(std::atof(cell.c_str()));
    }
    return values;
}

} // namespace testing
} // namespace ghostfx
