/// @file   RunCommand.cc
/// @brief  `ghostfx run`: scene -> solver -> frames, checkpoints, statistics and previews.
#include "RunCommand.h"

#include "LiquidScene.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/Preview.h>
#include <ghostfx/vdbio/Scene.h>
#include <ghostfx/vdbio/Stats.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <unistd.h>

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;
using ghost::GhostSolver;
using sph::ParticleKind;
using Clock = std::chrono::steady_clock;

// Ctrl-C -----------------------------------------------------------------------------------------
// The first SIGINT asks the run to stop after the current frame (its outputs and a checkpoint are
// written); the handler then restores the default action, so a second Ctrl-C abandons the frame
// at once. Every file is written atomically, so nothing is left half-written either way.

namespace {

std::atomic<bool> gInterrupted{false};

extern "C" void onInterrupt(int)
{
    gInterrupted.store(true);
    std::signal(SIGINT, SIG_DFL);
}

/// Installs the handler for the life of a run and restores the previous one.
class InterruptGuard
{
public:
    InterruptGuard()
    {
        gInterrupted.store(false);
        mPrevious = std::signal(SIGINT, onInterrupt);
    }
    ~InterruptGuard() { std::signal(SIGINT, mPrevious); }

private:
    void (*mPrevious)(int) = SIG_DFL;
};

double seconds(Clock::time_point a, Clock::time_point b)
{
    return std::chrono::duration<double>(b - a).count();
}

std::string duration(double s)
{
    char buffer[32];
    if (s < 60) std::snprintf(buffer, sizeof(buffer), "%.0fs", s);
    else if (s < 3600) std::snprintf(buffer, sizeof(buffer), "%dm%02ds", int(s) / 60, int(s) % 60);
    else std::snprintf(buffer, sizeof(buffer), "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
    return buffer;
}

/// Parse "--frames A-B" or "--frames B".
void parseFrames(const std::string& text, int& first, int& last)
{
    int a = 0, b = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%d-%d%c", &a, &b, &tail) == 2) {
        first = a;
        last = b;
    } else if (std::sscanf(text.c_str(), "%d%c", &b, &tail) == 1) {
        last = b;
    } else {
        throw ValueError(msg("--frames '", text, "': expected A-B (e.g. 1-48) or a last frame"));
    }
    if (first < 1 || last < first) {
        throw ValueError(msg("--frames '", text, "': expected 1 <= first <= last"));
    }
}

/// Progress on a terminal (one line redrawn) or as log lines.
class Progress
{
public:
    enum class Mode { None, Log, Bar };

    Progress(Mode mode, int first, int last) : mMode(mode), mFirst(first), mLast(last) {}

    void step(const GhostSolver& solver, int frame, int substep)
    {
        if (mMode != Mode::Bar) return;
        const auto now = Clock::now();
        if (seconds(mLastDraw, now) < 0.2) return;
        mLastDraw = now;
        const double elapsed = seconds(mStart, now);
        const double rate = elapsed > 0 ? double(mSteps) / elapsed : 0;
        const double done = double(frame - mFirst) + 0.0;
        const double total = double(mLast - mFirst + 1);
        const double eta = done > 0 ? elapsed * (total - done) / done : 0;
        const int width = 24;
        const int filled = int(width * done / total);
        std::fprintf(stderr, "\r\033[Kframe %d/%d [%s%s] substep %d | %zu liquid | %.1f steps/s | ETA %s",
                     frame, mLast, std::string(std::size_t(filled), '#').c_str(),
                     std::string(std::size_t(width - filled), '.').c_str(), substep,
                     solver.count(ParticleKind::Liquid), rate, done > 0 ? duration(eta).c_str() : "?");
        std::fflush(stderr);
    }

    void countStep() { ++mSteps; }

    void frame(const GhostSolver& solver, int frame, int steps, double frameSeconds, bool written)
    {
        if (mMode == Mode::None) return;
        if (mMode == Mode::Bar) std::fprintf(stderr, "\r\033[K");
        std::fprintf(stderr, "frame %d/%d: t = %.4f s, %d steps, %zu liquid, %zu air, %zu solid ghosts, %.2f s%s\n",
                     frame, mLast, solver.time(), steps, solver.count(ParticleKind::Liquid),
                     solver.count(ParticleKind::GhostAir),
                     solver.count(ParticleKind::GhostSolid) + solver.count(ParticleKind::Boundary),
                     frameSeconds, written ? "" : " (not written: before the first frame)");
        std::fflush(stderr);
    }

    void message(const std::string& text)
    {
        if (mMode == Mode::None) return;
        if (mMode == Mode::Bar) std::fprintf(stderr, "\r\033[K");
        std::fprintf(stderr, "%s\n", text.c_str());
    }

private:
    Mode mMode;
    int mFirst, mLast;
    std::uint64_t mSteps = 0;
    Clock::time_point mStart = Clock::now(), mLastDraw{};
};

/// Per-step statistics row.
vdbio::StatsRow statsRow(const GhostSolver& solver, int frame, double dt, const ghost::PhaseTimings& before)
{
    const sph::ParticleSet& p = solver.particles();
    const double rho0 = solver.settings().restDensity;
    double maxSpeed = 0, errorSum = 0, errorMax = 0;
    std::size_t liquid = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        ++liquid;
        maxSpeed = std::max(maxSpeed, double(p.velocities()[i].length()));
        const double e = std::abs(double(p.densities()[i]) / rho0 - 1.0);
        errorSum += e;
        errorMax = std::max(errorMax, e);
    }
    const ghost::PhaseTimings& t = solver.timings();
    vdbio::StatsRow row;
    row.values = {
        {"frame", frame},
        {"step", double(solver.stepCount())},
        {"time", solver.time()},
        {"dt", dt},
        {"count_liquid", double(liquid)},
        {"count_ghost_air", double(solver.count(ParticleKind::GhostAir))},
        {"count_ghost_solid", double(solver.count(ParticleKind::GhostSolid))},
        {"count_boundary", double(solver.count(ParticleKind::Boundary))},
        {"max_speed", maxSpeed},
        {"density_error_mean", liquid ? errorSum / double(liquid) : 0.0},
        {"density_error_max", errorMax},
        {"t_neighbors_density", t.neighborsAndDensity - before.neighborsAndDensity},
        {"t_pressure_force", t.pressureForce - before.pressureForce},
        {"t_xsph_boundary", t.xsphAndBoundary - before.xsphAndBoundary},
        {"t_air_resampling", t.airResampling - before.airResampling},
        {"t_emission", t.emission - before.emission},
        {"t_step", t.total - before.total},
        {"bytes_per_particle", p.size() ? double(p.memoryBytes()) / double(p.size()) : 0.0},
    };
    return row;
}

} // namespace

int runScene(const RunOptions& o)
{
    const auto runStart = Clock::now();
    parallel::ThreadLimit threadLimit(o.threads);

    // Scene, settings and outputs: every input error is found before any simulation.
    vdbio::Scene scene = vdbio::readScene(o.scene, o.defines);
    const ghost::GhostSettings settings = liquidSettings(scene);
    int first = scene.firstFrame, last = scene.lastFrame;
    if (!o.frames.empty()) parseFrames(o.frames, first, last);
    const vdbio::SceneOutputs& out = scene.outputs;
    const std::string folder = o.out.empty() ? out.directory : o.out;
    vdbio::ensureWritableDirectory(folder);
    auto inFolder = [&](const std::string& pattern, int frame) {
        return (fs::path(folder) / vdbio::expandFramePattern(pattern, frame)).string();
    };
    const std::string fingerprint = scene.simulationFingerprint();

    // The solver, fresh or from a checkpoint.
    std::unique_ptr<GhostSolver> solver;
    if (!o.resume.empty()) {
        const sph::SolverState state = vdbio::readCheckpoint(o.resume, fingerprint);
        solver = makeLiquidSolver(scene, settings, &state);
    } else {
        solver = makeLiquidSolver(scene, settings);
    }
    const int startFrame = solver->frame();

    Progress::Mode mode = Progress::Mode::Log;
    if (o.quiet || o.progress == "none") mode = Progress::Mode::None;
    else if (o.progress == "bar" || (o.progress == "auto" && ::isatty(STDERR_FILENO))) mode = Progress::Mode::Bar;
    Progress progress(mode, std::max(first, startFrame + 1), last);
    if (startFrame >= last) {
        progress.message(msg("nothing to do: the checkpoint is at frame ", startFrame, ", the last frame is ", last));
        return 0;
    }
    progress.message(msg("ghostfx run '", scene.file, "': ", scene.method, " method, spacing ", scene.spacing,
                         " m, frames ", std::max(first, startFrame + 1), "-", last, (o.resume.empty() ? "" : " (resumed from '" + o.resume + "')"),
                         ", ", parallel::maxThreads(), " threads, output in '", folder, "'"));

    // Statistics.
    std::unique_ptr<vdbio::StatsWriter> stats;
    if (!out.statsFile.empty()) {
        const std::string h5 = inFolder(out.statsFile, 0);
        const std::string csv = (fs::path(h5).replace_extension(".csv")).string();
        stats = std::make_unique<vdbio::StatsWriter>(h5, csv);
        if (!o.resume.empty()) stats->resumeFrom(std::int64_t(solver->stepCount()));
    }

    int frame = startFrame + 1, substep = 0;
    ghost::PhaseTimings before = solver->timings();
    solver->setStepObserver([&](const GhostSolver& s, sph::Real dt) {
        ++substep;
        progress.countStep();
        progress.step(s, frame, substep);
        if (stats) stats->append(statsRow(s, frame, double(dt), before));
        before = s.timings();
    });

    InterruptGuard interruptGuard;
    auto writeCheckpoint = [&](int f) {
        if (out.checkpointFile.empty()) return std::string();
        const std::string path = inFolder(out.checkpointFile, f);
        vdbio::writeCheckpoint(path, solver->saveState(), fingerprint, f);
        return path;
    };

    openvdb::MetaMap fileMeta;
    fileMeta.insertMeta("ghostfx_scene", openvdb::StringMetadata(scene.file));
    fileMeta.insertMeta("ghostfx_method", openvdb::StringMetadata(scene.method));

    std::uint64_t stepsAtStart = solver->stepCount();
    for (; frame <= last; ++frame) {
        const auto frameStart = Clock::now();
        const std::uint64_t stepsBefore = solver->stepCount();
        substep = 0;
        updateSolidSequences(scene, *solver, frame);
        solver->advanceFrame();

        const bool write = frame >= first;
        if (write) {
            fileMeta.insertMeta("frame", openvdb::Int32Metadata(frame));
            fileMeta.insertMeta("time", openvdb::DoubleMetadata(solver->time()));
            if (!out.pointsFile.empty()) {
                vdbio::PointsOptions po;
                po.channels = out.pointChannels;
                if (out.pointGhosts) {
                    po.kinds = {ParticleKind::Liquid, ParticleKind::GhostAir, ParticleKind::GhostSolid,
                                ParticleKind::Boundary};
                    if (std::find(po.channels.begin(), po.channels.end(), "kind") == po.channels.end()) {
                        po.channels.push_back("kind");
                    }
                }
                vdbio::writePointsFile(inFolder(out.pointsFile, frame), solver->particles(), po, fileMeta);
            }
            if (!out.volumeFile.empty()) {
                vdbio::VolumeOptions vo;
                vo.voxelSize = out.voxelSize > 0 ? out.voxelSize : 0.5 * scene.spacing;
                vo.kernelSupport = settings.supportRadius();
                vo.restDensity = settings.restDensity;
                vo.particleSpacing = scene.spacing;
                auto wants = [&](const char* g) {
                    return std::find(out.volumeGrids.begin(), out.volumeGrids.end(), g) != out.volumeGrids.end();
                };
                vo.surface = wants("surface");
                vo.density = wants("density");
                vo.velocity = wants("vel");
                const openvdb::GridPtrVec grids = vdbio::makeVolumeGrids(solver->particles(), vo);
                vdbio::writeVolumeFile(inFolder(out.volumeFile, frame), grids, fileMeta);
                if (!out.previewFile.empty()) {
                    vdbio::PreviewOptions pv;
                    pv.width = out.previewWidth;
                    pv.height = out.previewHeight;
                    std::string name = out.previewGrid;
                    if (name.empty()) name = vo.density ? "density" : "surface";
                    openvdb::GridBase::Ptr grid;
                    for (const auto& g : grids) {
                        if (g->getName() == name) grid = g;
                    }
                    if (!grid) {
                        throw SceneError(msg("scene '", scene.file, "': outputs.preview.grid = '", name,
                                             "': the volume output has no such grid"));
                    }
                    vdbio::renderPreview(*grid, pv, inFolder(out.previewFile, frame));
                }
            }
        }
        if (stats) stats->flush();
        const bool interrupted = gInterrupted.load();
        if (interrupted || frame == last ||
            (out.checkpointEvery > 0 && frame % out.checkpointEvery == 0)) {
            const std::string path = writeCheckpoint(frame);
            if (interrupted) {
                progress.frame(*solver, frame, int(solver->stepCount() - stepsBefore),
                               seconds(frameStart, Clock::now()), write);
                std::fprintf(stderr, "ghostfx: interrupted after frame %d%s\n", frame,
                             path.empty() ? " (checkpoints are off: nothing to resume from)"
                                          : ("; resume with: ghostfx run " + o.scene + " --resume " + path).c_str());
                return EXIT_INTERRUPTED;
            }
        }
        progress.frame(*solver, frame, int(solver->stepCount() - stepsBefore), seconds(frameStart, Clock::now()),
                       write);
    }
    const double total = seconds(runStart, Clock::now());
    const std::uint64_t steps = solver->stepCount() - stepsAtStart;
    const sph::ParticleSet& p = solver->particles();
    progress.message(msg("done: ", steps, " steps in ", duration(total), " (", total > 0 ? double(steps) / total : 0.0,
                         " steps/s), ", p.size(), " particles, ",
                         p.size() ? double(p.memoryBytes()) / double(p.size()) : 0.0, " bytes per particle"));
    return 0;
}

Command addRunCommand(CLI::App& parent)
{
    auto o = std::make_shared<RunOptions>();
    CLI::App* c = parent.add_subcommand("run", "Simulate a scene to a VDB frame sequence");
    c->add_option("scene", o->scene, "scene file (.json, or a .vdb whose grids carry ghostfx_role)")
        ->required();
    c->add_option("--frames", o->frames, "frames to write, A-B (default: settings.frame_range)");
    c->add_option("--threads", o->threads, "worker threads (0: all cores)")->check(CLI::NonNegativeNumber);
    c->add_option("--out", o->out, "output folder (default: outputs.directory)");
    c->add_option("-D,--define", o->defines, "override a scene key: -D settings.stiffness=5000")
        ->allow_extra_args(false);
    c->add_option("--resume", o->resume, "continue from this checkpoint (.h5)");
    c->add_flag("-q,--quiet", o->quiet, "print errors only");
    c->add_option("--progress", o->progress, "auto, bar, log or none")
        ->check(CLI::IsMember({"auto", "bar", "log", "none"}));
    return {c, [o] { return runScene(*o); }};
}

} // namespace cmd
} // namespace ghostfx
