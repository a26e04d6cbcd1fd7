/// @file   RunCommand.cc
/// @brief  `ghostfx run`: scene -> solver -> frames, checkpoints, statistics and previews.
#include "RunCommand.h"

#include "DistributedRun.h"
#include "FrameWriter.h"
#include "LiquidScene.h"
#include "OutputChecks.h"
#include "Progress.h"
#include "RunChecks.h"
#include "Simulation.h"
#include "StopSignals.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/BodyTable.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/Preview.h>
#include <ghostfx/vdbio/Scene.h>
#include <ghostfx/vdbio/ScenePreview.h>
#include <ghostfx/vdbio/Stats.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <unistd.h>

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;
using sph::ParticleKind;
using Clock = std::chrono::steady_clock;

void parseFrames(const std::string& text, int& first, int& last)
{
    // One whole number at p, no sign, at most MAX_FRAME; returns the end of it or nullptr.
    auto number = [](const char* p, long long& out) -> const char* {
        if (*p < '0' || *p > '9') return nullptr;
        out = 0;
        for (; *p >= '0' && *p <= '9'; ++p) {
            out = out * 10 + (*p - '0');
            if (out > vdbio::MAX_FRAME) return nullptr;
        }
        return p;
    };
    long long a = first, b = 0;
    const char* p = number(text.c_str(), b);
    if (p && *p == '-') {
        a = b;
        p = number(p + 1, b);
    }
    if (!p || *p != '\0') {
        throw ValueError(msg("--frames '", text,
                             "': expected A-B (e.g. 1-48) or a last frame, whole "
                             "numbers up to ",
                             vdbio::MAX_FRAME));
    }
    if (a < 1 || b < a) {
        throw ValueError(msg("--frames '", text, "': expected 1 <= first <= last"));
    }
    first = int(a);
    last = int(b);
}

namespace {


/// `text` as one shell word: as it is when it holds only characters no shell treats specially,
/// else in single quotes.
std::string shellWord(const std::string& text)
{
    const bool plain = !text.empty() && text.find_first_not_of("abcdefghijklmnopqrstuvwxyz"
                                                               "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                               "0123456789_./=:,+-@%^")
                                            == std::string::npos;
    if (plain) return text;
    std::string quoted = "'";
    for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

/// The command that continues this run from `checkpoint`: the same scene, output folder,
/// frames and overrides (a checkpoint is refused under other settings), on `ranks` processes.
std::string resumeCommand(const RunOptions& o, const std::string& checkpoint, int ranks)
{
    std::string command = ranks > 1 ? msg("mpirun -np ", ranks, " ") : std::string();
    command += "ghostfx run " + shellWord(o.scene);
    if (!o.out.empty()) command += " --out " + shellWord(o.out);
    if (!o.frames.empty()) command += " --frames " + shellWord(o.frames);
    for (const std::string& define : o.defines) command += " -D " + shellWord(define);
    if (!o.sampleCache.empty()) command += " --sample-cache " + shellWord(o.sampleCache);
    return command + " --resume " + shellWord(checkpoint);
}

/// Simulate one frame; a blow-up's message names the scene and the keys that set its step.
void advanceFrame(const vdbio::Scene& scene, Simulation& sim)
{
    try {
        sim.advanceFrame();
    } catch (const NumericalError& e) {
        throw NumericalError(
            msg("scene '", scene.file, "': ", e.what(), " (in this scene: ", stepKeys(scene), ")"));
    }
}

/// The media's particles, summed over the processes of a distributed run (collective).
std::vector<Simulation::MediumCount> mediumCounts(const Simulation& sim,
                                                  DistributedRun* distributed)
{
    std::vector<Simulation::MediumCount> counts = sim.mediumCounts();
    if (distributed) {
        for (auto& c : counts) c.count = std::size_t(distributed->sumOf(double(c.count)));
    }
    return counts;
}

/// The rows of bodies.csv for `frame`: every dynamic solid of `sim` at its time, named as the
/// scene names it (a solid a script added: solids[i]).
std::vector<vdbio::BodyRow> bodyRows(const vdbio::Scene& scene, const Simulation& sim, int frame)
{
    std::vector<vdbio::BodyRow> rows;
    for (const Simulation::BodySample& b : sim.bodies()) {
        vdbio::BodyRow row;
        row.frame = frame;
        row.time = sim.time();
        row.name = b.solid < scene.solids.size() ? scene.solids[b.solid].name
                                                 : msg("solids[", b.solid, "]");
        const sph::RigidBodyState& s = b.state;
        const sph::Quatd& q = s.orientation;
        row.values = {s.position[0],
                      s.position[1],
                      s.position[2],
                      q.w(),
                      q.x(),
                      q.y(),
                      q.z(),
                      s.velocity[0],
                      s.velocity[1],
                      s.velocity[2],
                      b.angularVelocity[0],
                      b.angularVelocity[1],
                      b.angularVelocity[2]};
        rows.push_back(std::move(row));
    }
    return rows;
}

/// Says once, when it happens, that a medium has no particles left (all through the kill box,
/// boiled away or at the end of their life): the run goes on and writes empty frames.
class EmptyMediaWatch
{
public:
    /// `start`: the media's particles before the first step.
    EmptyMediaWatch(const vdbio::Scene& scene, bool prints,
                    const std::vector<Simulation::MediumCount>& start)
        : mScene(scene)
        , mPrints(prints)
    {
        for (const Simulation::MediumCount& c : start) mLast[c.name] = c.count;
    }

    /// After `frame`: `counts` are the media's particles (over several processes, summed).
    void check(const std::vector<Simulation::MediumCount>& counts, int frame)
    {
        for (const Simulation::MediumCount& c : counts) {
            std::size_t& last = mLast[c.name];
            const bool emptied = last > 0 && c.count == 0;
            last = c.count;
            if (!emptied || !mPrints) continue;
            const bool liquid = c.name == "liquid";
            std::fprintf(stderr, "%s\n",
                         msg("ghostfx: warning: scene '", mScene.file, "', frame ", frame,
                             ": no ", c.name, " particles are left (",
                             liquid ? (mScene.heaters.empty()
                                           ? "all left the kill box"
                                           : "all left the kill box or boiled away")
                                    : "all left the kill box or reached their life_strength",
                             "); the run goes on and its ", c.name, " frames are empty until ",
                             liquid ? "an emitter pours" : "a source emits", " again")
                             .c_str());
        }
    }

private:
    const vdbio::Scene& mScene;
    bool mPrints;
    std::map<std::string, std::size_t> mLast;
};


/// One `ghostfx run`, as a sequence of named steps: the scene, the simulation (fresh or from a
/// checkpoint) and every check before any output; what the run says before its first step; the
/// statistics; the frames, each written, checkpointed and reported; how it ends. `distributed`
/// is null for a single process (else rank 0 writes, DistributedRun.h).
class SceneRun
{
public:
    SceneRun(const RunOptions& o, DistributedRun* distributed)
        : mOptions(o)
        , mDistributed(distributed)
        , mWrites(!distributed || distributed->root())
        , mThreadLimit(o.threads)
    {
        if (!o.sampleCache.empty()) setProcessSampleCache(o.sampleCache);
    }

    int run()
    {
        readScene();
        refuseDistributedBodies();
        makeSimulation();
        checkBeforeOutput();
        makeProgress();
        if (mSim->frame() >= mLast) {
            mProgress->message(msg("nothing to do: the checkpoint is at frame ", mSim->frame(),
                                   ", the last frame is ", mLast));
            return 0;
        }
        announce();
        openStatistics();
        return runFrames();
    }

private:
    /// The scene, its frames and folder: every input error before any simulation.
    void readScene()
    {
        mScene = vdbio::readScene(mOptions.scene, mOptions.defines);
        mFirst = mScene.firstFrame;
        mLast = mScene.lastFrame;
        if (!mOptions.frames.empty()) parseFrames(mOptions.frames, mFirst, mLast);
        mFolder = mOptions.out.empty() ? mScene.outputs.directory : mOptions.out;
        mFingerprint = checkpointFingerprint(mScene);
    }

    /// Dynamic solids run on one process: over several, refused before any simulation, said
    /// once, by the first process (the others wait for its error to stop them, runScene).
    void refuseDistributedBodies()
    {
        if (!mDistributed) return;
        for (std::size_t i = 0; i < mScene.solids.size(); ++i) {
            if (!mScene.solids[i].dynamic) continue;
            if (!mDistributed->root()) awaitDistributedAbort();
            throw SceneError(msg("scene '", mScene.file, "': solids[", i, "].dynamic: solid '",
                                 mScene.solids[i].name,
                                 "' is dynamic, and dynamic solids run on "
                                 "one process: run this scene without mpirun"));
        }
    }

    /// The solvers the scene needs, fresh or from a checkpoint.
    void makeSimulation()
    {
        if (mOptions.resume.empty()) {
            mSim = cmd::makeSimulation(mScene);
            return;
        }
        std::vector<sph::SolverState> states = readResumeStates();
        mSim = cmd::makeSimulation(mScene, &states);
    }

    /// A checkpoint a Python script wrote with solids, emitters or gas sources it added holds
    /// them as attachments the scene file does not have: refused, naming where it resumes.
    static void refuseScriptAdditions(const std::string& path)
    {
        const vdbio::CheckpointAttachments attachments = vdbio::readCheckpointAttachments(path);
        if (attachments.empty()) return;
        std::string names;
        for (const auto& [name, bytes] : attachments) names += (names.empty() ? "" : ", ") + name;
        throw SceneError(msg("--resume '", path, "': the checkpoint holds what a Python script "
                             "added to the scene (attachments ", names, "); resume it from the "
                             "script with ghostfx.Simulation.resume(scene, '", path, "')"));
    }

    /// A run over several processes resumes from its manifest: on as many processes, each from
    /// its own file, with the saved regions (bit for bit); on another count (one process
    /// included), every process reads every file and the domain is cut anew. A one-process
    /// checkpoint resumed on several processes is cut the same way.
    std::vector<sph::SolverState> readResumeStates()
    {
        if (!isDistributedManifest(mOptions.resume)) {
            refuseScriptAdditions(mOptions.resume);
            return vdbio::readCheckpointStates(mOptions.resume, mFingerprint);
        }
        const int here = mDistributed ? mDistributed->ranks() : 1;
        mManifest = readDistributedManifest(mOptions.resume);
        if (mManifest->ranks == here) {
            const int rank = mDistributed ? mDistributed->rank() : 0;
            return {vdbio::readCheckpoint(mManifest->files[std::size_t(rank)], mFingerprint)};
        }
        std::vector<sph::SolverState> parts;
        for (const std::string& file : mManifest->files)
            parts.push_back(vdbio::readCheckpoint(file, mFingerprint));
        mResumeNote = msg("note: '", mOptions.resume, "' was written by ", mManifest->ranks,
                          " processes and this run has ", here, ": its parts are merged",
                          here > 1 ? " and the domain cut anew" : "",
                          " (the run goes on, but not bit for bit as it would have on ",
                          mManifest->ranks, ")");
        mManifest.reset();
        return {mergeProcessStates(std::move(parts))};
    }

    /// What would fail after the first frame fails now, before anything is written; then the
    /// processes share the simulation and the output folder is made.
    void checkBeforeOutput()
    {
        checkSolidSequences(mScene, mSim->frame() + 1, mLast);
        checkOutputs(mScene, *mSim);
        checkStepsPerFrame(mScene, *mSim);
        if (mDistributed)
            mDistributed->share(*mSim, mManifest ? &mManifest->decomposition : nullptr);
        if (mWrites) {
            vdbio::ensureWritableDirectory(mFolder);
            checkOutputFolders(mScene, mFolder);
        }
    }

    void makeProgress()
    {
        const RunOptions& o = mOptions;
        Progress::Mode mode = Progress::Mode::Log;
        if (o.quiet || o.progress == "none" || !mWrites) mode = Progress::Mode::None;
        else if (o.progress == "bar" || (o.progress == "auto" && ::isatty(STDERR_FILENO)))
            mode = Progress::Mode::Bar;
        mProgress = std::make_unique<Progress>(mode, std::max(mFirst, mSim->frame() + 1), mLast);
        if (!mResumeNote.empty()) mProgress->message(mResumeNote);
        reportSampleCache();
    }

    void reportSampleCache()
    {
        const vdbio::SampleCache* cache = processSampleCacheIfMade();
        if (!cache) return;
        mProgress->message(msg("sample cache '", cache->folder(), "': ", cache->hits(),
                               " shapes loaded, ", cache->stored(), " sampled and kept",
                               cache->evicted() > 0
                                   ? msg(", ", cache->evicted(), " least recently used removed")
                                   : std::string()));
        if (cache->failures() > 0 && mWrites) {
            std::fprintf(stderr,
                         "ghostfx: warning: sample cache: %llu shapes could not be kept "
                         "(%s); the run goes on without them\n",
                         static_cast<unsigned long long>(cache->failures()),
                         cache->firstFailure().c_str());
        }
    }

    /// The run's first line, its warnings, and what each emitter pours (so a wrong velocity or
    /// shape shows before the run).
    void announce()
    {
        const vdbio::Scene& scene = mScene;
        const std::size_t fields = scene.forceFields.size();
        mProgress->message(msg(
            "ghostfx run '", scene.file, "': ", scene.method,
            scene.heaters.empty() ? "" : " + boiling",
            fields == 0 ? "" : msg(" + ", fields, fields == 1 ? " attractor" : " attractors"),
            ", spacing ", scene.spacing, " m, frames ", std::max(mFirst, mSim->frame() + 1), "-",
            mLast, (mOptions.resume.empty() ? "" : " (resumed from '" + mOptions.resume + "')"),
            ", ", parallel::maxThreads(), " threads",
            mDistributed ? msg(" on each of ", mDistributed->ranks(), " processes") : "",
            ", output in '", mFolder, "'"));
        warnFixedStepBeyondTheLimit(scene, *mSim, mWrites);
        const auto rates = mSim->emitterRates();
        for (std::size_t e = 0; e < rates.size() && e < scene.emitters.size(); ++e) {
            const vdbio::SceneEmitter& em = scene.emitters[e];
            mProgress->message(msg("emitter '", em.name, "': ", em.velocity.length(),
                                   " m/s through ", std::round(rates[e].crossSection * 1e6) / 100,
                                   " cm^2 = ", std::round(rates[e].massRate * 100) / 100,
                                   " kg/s from ", em.start, " s",
                                   std::isfinite(em.end) ? msg(" to ", em.end, " s") : ""));
        }
        if (mWrites) warnThinSolids(scene, mSim->boundaryLayerDepth());
        if (mDistributed && scene.outputs.pointGhosts && !scene.outputs.pointsFile.empty()) {
            mProgress->message("note: outputs.points.ghosts: over several processes the points "
                               "files hold the liquid only (the ghosts stay with their processes)");
        }
    }

    /// Per-step statistics; over several processes rank 0 writes the rows combined from every
    /// process's.
    void openStatistics()
    {
        const vdbio::SceneOutputs& out = mScene.outputs;
        if (!out.statsFile.empty() && mWrites) {
            const std::string h5 = inFolder(out.statsFile, 0);
            const std::string csv = (fs::path(h5).replace_extension(".csv")).string();
            mStats = std::make_unique<vdbio::StatsWriter>(h5, csv);
            if (!mOptions.resume.empty()) mStats->resumeFrom(std::int64_t(mSim->stepCount()));
        }
        if (mWrites && !mSim->bodies().empty()) {
            mBodies = std::make_unique<vdbio::BodyLog>(inFolder("bodies.csv", 0));
            if (!mOptions.resume.empty()) mBodies->resumeFrom(mSim->frame());
        }
        const bool combine = !out.statsFile.empty() && mDistributed;
        mSim->setStepObserver([this, combine](double dt) {
            ++mSubstep;
            mProgress->countStep();
            mProgress->step(*mSim, mFrame, mSubstep);
            if (combine) {
                const vdbio::StatsRow row = mDistributed->combine(mSim->statsRow(mFrame, dt));
                if (mStats) mStats->append(row);
            } else if (mStats) {
                mStats->append(mSim->statsRow(mFrame, dt));
            }
        });
    }

    /// Every frame to the last, or to the one after which a signal asked to stop.
    int runFrames()
    {
        const StopSignals stopSignals;
        EmptyMediaWatch emptyMedia(mScene, mWrites, mediumCounts(*mSim, mDistributed));
        // Frame N's files are written while frame N + 1 simulates (FrameWriter.h).
        FrameWriter writer(mScene, mFolder, !mOptions.serialOutput);
        const std::uint64_t stepsAtStart = mSim->stepCount();
        for (mFrame = mSim->frame() + 1; mFrame <= mLast; ++mFrame) {
            const int stopSignal = runFrame(writer);
            emptyMedia.check(mediumCounts(*mSim, mDistributed), mFrame);
            if (stopSignal != 0) return StopSignals::exitCode(stopSignal);
        }
        writer.finish();
        for (const std::string& note : writer.takeNotes()) mProgress->message(note);
        reportDone(mSim->stepCount() - stepsAtStart);
        return 0;
    }

    /// Simulate, write and report frame mFrame; returns the stop signal seen by any process
    /// (0: none), after writing the frame's checkpoint for it.
    int runFrame(FrameWriter& writer)
    {
        const auto frameStart = Clock::now();
        const std::uint64_t stepsBefore = mSim->stepCount();
        mSubstep = 0;
        mSim->beforeFrame(mFrame);
        advanceFrame(mScene, *mSim);
        const bool write = mFrame >= mFirst;
        if (write && mDistributed) {
            FrameSnapshot snapshot = mDistributed->snapshot(mScene.outputs, *mSim, mFrame);
            if (mWrites) writer.submit(std::move(snapshot));
        } else if (write) {
            writer.submit(snapshotFrame(mScene.outputs, *mSim, mFrame));
        }
        recordBodies();
        if (mStats) mStats->flush();
        // Every process stops at the same frame, whichever saw the signal, and all report the
        // same one.
        const int stopSignal = mDistributed
                                   ? int(mDistributed->maxOf(double(StopSignals::received())))
                                   : StopSignals::received();
        const vdbio::SceneOutputs& out = mScene.outputs;
        std::string checkpoint;
        if (stopSignal != 0 || mFrame == mLast
            || (out.checkpointEvery > 0 && mFrame % out.checkpointEvery == 0)) {
            writer.finish(); // the frames on disk reach at least as far as the checkpoint
            checkpoint = writeCheckpoint();
        }
        // Over several processes the counts are every process's, summed (collective).
        mProgress->frame(*mSim, mDistributed ? mDistributed->counts(*mSim) : mSim->counts(),
                         mFrame, int(mSim->stepCount() - stepsBefore),
                         secondsBetween(frameStart, Clock::now()), write);
        for (const std::string& note : writer.takeNotes()) mProgress->message(note);
        if (stopSignal != 0) reportStop(stopSignal, checkpoint);
        return stopSignal;
    }

    /// The dynamic solids' rows of mFrame, into bodies.csv and the statistics' `/bodies`.
    void recordBodies()
    {
        if (!mBodies) return;
        for (vdbio::BodyRow& row : bodyRows(mScene, *mSim, mFrame)) mBodies->append(std::move(row));
        mBodies->flush();
        if (mStats) mStats->setBodies(mBodies->rows());
    }

    /// The checkpoint of mFrame, if the scene asks for checkpoints; returns the path to resume
    /// from (over several processes, the manifest of a file per process).
    std::string writeCheckpoint()
    {
        const vdbio::SceneOutputs& out = mScene.outputs;
        if (out.checkpointFile.empty()) return std::string();
        const std::string path = inFolder(out.checkpointFile, mFrame);
        if (mDistributed) return mDistributed->writeCheckpoint(path, *mSim, mFingerprint, mFrame);
        vdbio::writeCheckpoint(path, mSim->saveStates(), mFingerprint, mFrame);
        return path;
    }

    void reportStop(int signal, const std::string& checkpoint) const
    {
        if (!mWrites) return;
        const int ranks = mDistributed ? mDistributed->ranks() : 1;
        std::fprintf(stderr, "ghostfx: stopped by %s after frame %d%s\n",
                     StopSignals::describe(signal), mFrame,
                     checkpoint.empty()
                         ? " (no checkpoint: nothing to resume from)"
                         : ("; resume with: " + resumeCommand(mOptions, checkpoint, ranks)).c_str());
    }

    void reportDone(std::uint64_t steps)
    {
        const double total = secondsBetween(mStart, Clock::now());
        const std::string done = msg("done: ", steps, " steps in ", duration(total), " (",
                                     total > 0 ? double(steps) / total : 0.0, " steps/s), ");
        if (mDistributed) {
            mProgress->message(done + mDistributed->counts(*mSim));
            return;
        }
        const std::size_t n = mSim->particleCount();
        mProgress->message(msg(done, n, " particles, ",
                               n ? double(mSim->memoryBytes()) / double(n) : 0.0,
                               " bytes per particle"));
    }

    std::string inFolder(const std::string& pattern, int frame) const
    {
        return pattern.empty()
                   ? std::string()
                   : (fs::path(mFolder) / vdbio::expandFramePattern(pattern, frame)).string();
    }

    const RunOptions& mOptions;
    DistributedRun* mDistributed;
    const bool mWrites;
    const Clock::time_point mStart = Clock::now();
    parallel::ThreadLimit mThreadLimit;
    vdbio::Scene mScene; ///< before mSim: the simulation keeps a reference to it
    int mFirst = 1, mLast = 1;
    std::string mFolder, mFingerprint;
    std::optional<DistributedManifest> mManifest; ///< resuming on the count that wrote it
    std::string mResumeNote;
    std::unique_ptr<Simulation> mSim;
    std::unique_ptr<Progress> mProgress;
    std::unique_ptr<vdbio::StatsWriter> mStats;
    std::unique_ptr<vdbio::BodyLog> mBodies; ///< with dynamic solids: bodies.csv
    int mFrame = 0, mSubstep = 0; ///< what the step observer reports
};

} // namespace

int runScene(const RunOptions& o)
{
    // Under mpirun: one simulation over the processes.
    const std::unique_ptr<DistributedRun> distributed = DistributedRun::startIfLaunched();
    if (!distributed) return SceneRun(o, nullptr).run();
    try {
        return SceneRun(o, distributed.get()).run();
    } catch (const std::exception& e) {
        // An error on one process would leave the others waiting for it: say it, stop all.
        std::fprintf(stderr, "ghostfx: error: process %d of %d: %s\n", distributed->rank(),
                     distributed->ranks(), e.what());
        abortDistributedRun(1);
        throw;
    }
}

Command addRunCommand(CLI::App& parent)
{
    auto o = std::make_shared<RunOptions>();
    CLI::App* c = parent.add_subcommand("run", "Simulate a scene to a VDB frame sequence");
    c->add_option("scene", o->scene, "scene file (.json, or a .vdb whose grids carry ghostfx_role)")
        ->required();
    c->add_option("--frames", o->frames, "frames to write, A-B (default: settings.frame_range)");
    c->add_option("--threads", o->threads, "worker threads (0: all cores)")
        ->check(CLI::NonNegativeNumber);
    c->add_option("--out", o->out, "output folder (default: outputs.directory)");
    c->add_option("-D,--define", o->defines, "override a scene key: -D settings.stiffness=5000")
        ->allow_extra_args(false);
    c->add_option("--resume", o->resume, "continue from this checkpoint (.h5)");
    c->add_flag("-q,--quiet", o->quiet,
                "no progress or log lines: print warnings and errors only");
    c->add_flag("--serial-output", o->serialOutput,
                "write each frame's files before simulating the next (by default they are "
                "written while the next frame simulates, holding up to two copies of the "
                "output particles)");
    c->add_option("--progress", o->progress, "auto, bar, log or none")
        ->check(CLI::IsMember({"auto", "bar", "log", "none"}));
    c->add_option("--sample-cache", o->sampleCache,
                  "keep the samples of solids and liquid bodies in this folder and take them "
                  "from it when the same shape is sampled again (default: "
                  "$GHOSTFX_SAMPLE_CACHE, else $XDG_CACHE_HOME/ghostfx/samples or "
                  "~/.cache/ghostfx/samples, kept within $GHOSTFX_SAMPLE_CACHE_LIMIT_MB, 2048 MiB; "
                  "'off': none); results are the same bit for bit");
    return {c, [o] { return runScene(*o); }};
}

} // namespace cmd
} // namespace ghostfx
