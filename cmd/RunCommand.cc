/// @file   RunCommand.cc
/// @brief  `ghostfx run`: scene -> solver -> frames, checkpoints, statistics and previews.
#include "RunCommand.h"

#include "DistributedRun.h"
#include "FrameWriter.h"
#include "LiquidScene.h"
#include "OutputChecks.h"
#include "RunChecks.h"
#include "Simulation.h"
#include "StopSignals.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/vdbio/AtomicFile.h>
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

namespace {

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

/// Parse "--frames A-B" or "--frames B" (whole numbers in [1, MAX_FRAME], first <= last).
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

/// Progress on a terminal (one line redrawn) or as log lines.
class Progress
{
public:
    enum class Mode { None, Log, Bar };

    Progress(Mode mode, int first, int last) : mMode(mode), mFirst(first), mLast(last) {}

    void step(const Simulation& sim, int frame, int substep)
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
        std::fprintf(stderr, "\r\033[Kframe %d/%d [%s%s] substep %d | %s | %.1f steps/s | ETA %s",
                     frame, mLast, std::string(std::size_t(filled), '#').c_str(),
                     std::string(std::size_t(width - filled), '.').c_str(), substep,
                     sim.counts().c_str(), rate, done > 0 ? duration(eta).c_str() : "?");
        std::fflush(stderr);
    }

    void countStep() { ++mSteps; }

    /// `counts`: the particles, as Simulation::counts() (or DistributedRun::counts()) says.
    void frame(const Simulation& sim, const std::string& counts, int frame, int steps,
               double frameSeconds, bool written)
    {
        if (mMode == Mode::None) return;
        if (mMode == Mode::Bar) std::fprintf(stderr, "\r\033[K");
        std::fprintf(stderr, "frame %d/%d: t = %.4f s, %d steps, %s, %.2f s%s\n", frame, mLast,
                     sim.time(), steps, counts.c_str(), frameSeconds,
                     written ? "" : " (not written: before the first frame)");
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

} // namespace

namespace {

/// The world box of the media's active voxels.
openvdb::BBoxd mediaBox(const std::vector<vdbio::PreviewLayer>& media)
{
    openvdb::BBoxd box;
    for (const vdbio::PreviewLayer& l : media) {
        const openvdb::CoordBBox ibox = l.grid->evalActiveVoxelBoundingBox();
        if (ibox.empty()) continue;
        box.expand(l.grid->indexToWorld(ibox.min()));
        box.expand(l.grid->indexToWorld(ibox.max()));
    }
    return box;
}

/// The scene's solids where they are at the snapshot's time (rigid motion from the scene's keys
/// or velocity, a per-frame shape from its file), as preview layers. A solid around the media's
/// centre (the centre is inside its box but outside the solid: a tank) is cut away so what it
/// holds shows.
std::vector<vdbio::PreviewLayer> solidLayers(const vdbio::Scene& scene,
                                             const FrameSnapshot& snapshot,
                                             const openvdb::BBoxd& media)
{
    std::vector<vdbio::PreviewLayer> layers;
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const vdbio::SceneSolid& solid = scene.solids[i];
        sph::LevelSet shape = solid.shape;
        if (!solid.sequenceFile.empty()) {
            shape = vdbio::loadLevelSet(
                vdbio::expandFramePattern(solid.sequenceFile, snapshot.frame), solid.sequenceGrid,
                msg("scene '", scene.file, "': solids[", i, "].sequence"));
        }
        vdbio::PreviewLayer layer;
        layer.name = solid.name;
        layer.grid = sph::gridOf(shape);
        layer.albedo = vdbio::SOLID_ALBEDO;
        // A solid that neither moves nor changes shape looks the same in every frame.
        layer.fixed = solid.isStatic();
        if (solid.motion.keys.empty()) {
            layer.translation = solid.velocity * snapshot.time;
        } else {
            const vdbio::RigidKey key = solid.motion.at(snapshot.time);
            layer.rotation = vdbio::KeyedMotion::rotation(key.rotateDegrees);
            layer.translation = key.translate;
        }
        if (media.max().x() >= media.min().x()) {
            const openvdb::Vec3d centre = media.getCenter();
            const openvdb::Vec3d local = layer.rotation.transpose() * (centre - layer.translation);
            // The level set keeps its active box (walking a large solid's tree every frame cost
            // more than drawing it).
            const sph::Aabb b = shape.bounds();
            const openvdb::BBoxd box(openvdb::Vec3d(b.min), openvdb::Vec3d(b.max));
            layer.cutaway = box.isInside(local) && shape.phi(sph::Vec3(local)) > 0;
        }
        layers.push_back(layer);
    }
    return layers;
}

/// Write one medium's points and volume files for `frame`; returns its grids (for previews).
/// `built`: the grids already built (a run over several processes), else built here.
openvdb::GridPtrVec writeMedium(const OutputMedium& m, const vdbio::SceneOutputs& out,
                                const std::string& pointsPath, const std::string& volumePath,
                                const openvdb::MetaMap& fileMeta, const BuiltGrids* built)
{
    if (!pointsPath.empty()) {
        if (built) {
            vdbio::writePointsGridFile(pointsPath, built->points, fileMeta);
        } else if (out.pointGhosts && m.withGhosts) {
            vdbio::writePointsFile(pointsPath, m.withGhosts(), pointsOptions(m, out), fileMeta);
        } else {
            vdbio::writePointsFile(pointsPath, *m.particles, pointsOptions(m, out), fileMeta);
        }
    }
    if (volumePath.empty()) return {};
    const openvdb::GridPtrVec grids =
        built ? built->volumes : vdbio::makeVolumeGrids(*m.particles, volumeOptions(m, out));
    vdbio::writeVolumeFile(volumePath, grids, fileMeta);
    return grids;
}

} // namespace

void writeFrameOutputs(const vdbio::Scene& scene, const FrameSnapshot& snapshot,
                       const std::string& folder, vdbio::PreviewCache* previewCache)
{
    const int frame = snapshot.frame;
    const vdbio::SceneOutputs& out = scene.outputs;
    auto inFolder = [&](const std::string& pattern) {
        return pattern.empty()
                   ? std::string()
                   : (fs::path(folder) / vdbio::expandFramePattern(pattern, frame)).string();
    };
    openvdb::MetaMap fileMeta;
    fileMeta.insertMeta("ghostfx_scene", openvdb::StringMetadata(scene.file));
    fileMeta.insertMeta("ghostfx_method", openvdb::StringMetadata(scene.method));
    fileMeta.insertMeta("frame", openvdb::Int32Metadata(frame));
    fileMeta.insertMeta("time", openvdb::DoubleMetadata(snapshot.time));
    // The media's grids as preview layers: the liquid's surface (else its density), the gas's
    // density, or the grid outputs.preview.grid names.
    std::vector<vdbio::PreviewLayer> media;
    bool namedGridFound = false;
    for (const OutputMedium& m : snapshot.media) {
        const bool liquid = m.liquid;
        const std::size_t index = std::size_t(&m - snapshot.media.data());
        const openvdb::GridPtrVec grids =
            writeMedium(m, out, inFolder(liquid ? out.pointsFile : out.gasPointsFile),
                        inFolder(liquid ? out.volumeFile : out.gasVolumeFile), fileMeta,
                        index < snapshot.built.size() ? &snapshot.built[index] : nullptr);
        if (out.previewFile.empty()) continue;
        // outputs.preview.grid where the medium has it, else the medium's default.
        std::vector<std::string> wanted = liquid ? std::vector<std::string>{"surface", "density"}
                                                 : std::vector<std::string>{"density"};
        if (!out.previewGrid.empty()) wanted.insert(wanted.begin(), out.previewGrid);
        for (const std::string& name : wanted) {
            auto g = std::find_if(grids.begin(), grids.end(),
                                  [&](const auto& grid) { return grid->getName() == name; });
            auto floatGrid =
                g == grids.end() ? nullptr : openvdb::gridPtrCast<openvdb::FloatGrid>(*g);
            if (!floatGrid) continue;
            vdbio::PreviewLayer layer;
            layer.name = m.name + " " + name;
            layer.grid = floatGrid;
            layer.kind = floatGrid->getGridClass() == openvdb::GRID_LEVEL_SET
                             ? vdbio::PreviewLayer::Kind::Surface
                             : vdbio::PreviewLayer::Kind::Fog;
            layer.albedo = liquid ? vdbio::LIQUID_ALBEDO : vdbio::GAS_ALBEDO;
            media.push_back(layer);
            namedGridFound = namedGridFound || name == out.previewGrid;
            break;
        }
    }
    if (out.previewFile.empty()) return;
    if (media.empty() || (!out.previewGrid.empty() && !namedGridFound)) {
        throw SceneError(msg("scene '", scene.file, "': outputs.preview.grid = '",
                             out.previewGrid.empty() ? "(default)" : out.previewGrid,
                             "': the volume output has no such grid"));
    }
    std::vector<vdbio::PreviewLayer> layers;
    if (out.previewSolids) layers = solidLayers(scene, snapshot, mediaBox(media));
    layers.insert(layers.end(), media.begin(), media.end());
    vdbio::PreviewOptions pv;
    pv.width = out.previewWidth;
    pv.height = out.previewHeight;
    pv.azimuth = out.previewAzimuth;
    pv.elevation = out.previewElevation;
    if (out.previewBackground) {
        const auto& c = *out.previewBackground;
        pv.background = {float(c[0]), float(c[1]), float(c[2]), 1.0f};
    }
    openvdb::BBoxd framed; // empty: the camera frames everything drawn
    if (!out.previewFrame.empty()) {
        framed = openvdb::BBoxd(openvdb::Vec3d(out.previewFrame.min),
                                openvdb::Vec3d(out.previewFrame.max));
    }
    vdbio::renderScenePreview(layers, pv, framed, inFolder(out.previewFile), previewCache);
}

/// The run; `distributed` is null for a single process (else rank 0 writes, DistributedRun.h).
int runSceneWith(const RunOptions& o, DistributedRun* distributed)
{
    const auto runStart = Clock::now();
    parallel::ThreadLimit threadLimit(o.threads);
    const bool writes = !distributed || distributed->root();
    if (!o.sampleCache.empty()) setProcessSampleCache(o.sampleCache);

    // Scene, settings and outputs: every input error is found before any simulation.
    vdbio::Scene scene = vdbio::readScene(o.scene, o.defines);
    int first = scene.firstFrame, last = scene.lastFrame;
    if (!o.frames.empty()) parseFrames(o.frames, first, last);
    const vdbio::SceneOutputs& out = scene.outputs;
    const std::string folder = o.out.empty() ? out.directory : o.out;
    const std::string fingerprint = scene.simulationFingerprint();

    // The solvers the scene needs, fresh or from a checkpoint.
    std::unique_ptr<Simulation> sim;
    std::optional<DistributedManifest> manifest; // resuming on the count that wrote it
    std::string resumeNote;
    if (!o.resume.empty()) {
        // A run over several processes resumes from its manifest: on as many processes, each
        // from its own file, with the saved regions (bit for bit); on another count (one
        // process included), every process reads every file and the domain is cut anew. A
        // one-process checkpoint resumed on several processes is cut the same way.
        std::vector<sph::SolverState> states;
        const int here = distributed ? distributed->ranks() : 1;
        if (isDistributedManifest(o.resume)) {
            manifest = readDistributedManifest(o.resume);
            if (manifest->ranks == here) {
                states.push_back(vdbio::readCheckpoint(
                    manifest->files[std::size_t(distributed ? distributed->rank() : 0)],
                    fingerprint));
            } else {
                std::vector<sph::SolverState> parts;
                for (const std::string& file : manifest->files)
                    parts.push_back(vdbio::readCheckpoint(file, fingerprint));
                states.push_back(mergeProcessStates(std::move(parts)));
                resumeNote = msg("note: '", o.resume, "' was written by ", manifest->ranks,
                                 " processes and this run has ", here, ": its parts are merged",
                                 here > 1 ? " and the domain cut anew" : "",
                                 " (the run goes on, but not bit for bit as it would have on ",
                                 manifest->ranks, ")");
                manifest.reset();
            }
        } else {
            states = vdbio::readCheckpointStates(o.resume, fingerprint);
        }
        sim = makeSimulation(scene, &states);
    } else {
        sim = makeSimulation(scene);
    }
    checkSolidSequences(scene, sim->frame() + 1, last);
    checkOutputs(scene, *sim);
    checkStepsPerFrame(scene, *sim);
    if (distributed) distributed->share(*sim, manifest ? &manifest->decomposition : nullptr);
    if (writes) vdbio::ensureWritableDirectory(folder);
    auto inFolder = [&](const std::string& pattern, int frame) {
        return pattern.empty()
                   ? std::string()
                   : (fs::path(folder) / vdbio::expandFramePattern(pattern, frame)).string();
    };
    const int startFrame = sim->frame();

    Progress::Mode mode = Progress::Mode::Log;
    if (o.quiet || o.progress == "none" || !writes) mode = Progress::Mode::None;
    else if (o.progress == "bar" || (o.progress == "auto" && ::isatty(STDERR_FILENO)))
        mode = Progress::Mode::Bar;
    Progress progress(mode, std::max(first, startFrame + 1), last);
    if (!resumeNote.empty()) progress.message(resumeNote);
    if (const vdbio::SampleCache* cache = processSampleCacheIfMade()) {
        progress.message(msg("sample cache '", cache->folder(), "': ", cache->hits(),
                             " shapes loaded, ", cache->stored(), " sampled and kept",
                             cache->evicted() > 0
                                 ? msg(", ", cache->evicted(), " least recently used removed")
                                 : std::string()));
        if (cache->failures() > 0 && writes) {
            std::fprintf(stderr,
                         "ghostfx: warning: sample cache: %llu shapes could not be kept "
                         "(%s); the run goes on without them\n",
                         static_cast<unsigned long long>(cache->failures()),
                         cache->firstFailure().c_str());
        }
    }
    if (startFrame >= last) {
        progress.message(msg("nothing to do: the checkpoint is at frame ", startFrame,
                             ", the last frame is ", last));
        return 0;
    }
    progress.message(msg(
        "ghostfx run '", scene.file, "': ", scene.method, scene.heaters.empty() ? "" : " + boiling",
        scene.forceFields.empty()
            ? ""
            : msg(" + ", scene.forceFields.size(),
                  scene.forceFields.size() == 1 ? " attractor" : " attractors"),
        ", spacing ", scene.spacing, " m, frames ", std::max(first, startFrame + 1), "-", last,
        (o.resume.empty() ? "" : " (resumed from '" + o.resume + "')"), ", ",
        parallel::maxThreads(), " threads",
        distributed ? msg(" on each of ", distributed->ranks(), " processes") : std::string(),
        ", output in '", folder, "'"));
    warnFixedStepBeyondTheLimit(scene, *sim, writes);
    // What each emitter pours, so a wrong velocity or shape shows before the run.
    const auto rates = sim->emitterRates();
    for (std::size_t e = 0; e < rates.size() && e < scene.emitters.size(); ++e) {
        const vdbio::SceneEmitter& em = scene.emitters[e];
        progress.message(msg("emitter '", em.name, "': ", em.velocity.length(), " m/s through ",
                             std::round(rates[e].crossSection * 1e6) / 100, " cm^2 = ",
                             std::round(rates[e].massRate * 100) / 100, " kg/s from ", em.start,
                             " s", std::isfinite(em.end) ? msg(" to ", em.end, " s") : ""));
    }
    if (writes) warnThinSolids(scene, sim->boundaryLayerDepth());
    const bool checkpoints = !out.checkpointFile.empty();

    // Statistics.
    // Over several processes, rank 0 writes the rows combined from every process's.
    std::unique_ptr<vdbio::StatsWriter> stats;
    const bool combineStats = !out.statsFile.empty() && distributed;
    if (distributed && out.pointGhosts && !out.pointsFile.empty()) {
        progress.message("note: outputs.points.ghosts: over several processes the points files "
                         "hold the liquid only (the ghosts stay with their processes)");
    }
    if (!out.statsFile.empty() && writes) {
        const std::string h5 = inFolder(out.statsFile, 0);
        const std::string csv = (fs::path(h5).replace_extension(".csv")).string();
        stats = std::make_unique<vdbio::StatsWriter>(h5, csv);
        if (!o.resume.empty()) stats->resumeFrom(std::int64_t(sim->stepCount()));
    }

    int frame = startFrame + 1, substep = 0;
    sim->setStepObserver([&](double dt) {
        ++substep;
        progress.countStep();
        progress.step(*sim, frame, substep);
        if (combineStats) {
            const vdbio::StatsRow row = distributed->combine(sim->statsRow(frame, dt));
            if (stats) stats->append(row);
        } else if (stats) {
            stats->append(sim->statsRow(frame, dt));
        }
    });

    StopSignals stopSignals;
    EmptyMediaWatch emptyMedia(scene, writes, mediumCounts(*sim, distributed));
    // Frame N's files are written while frame N + 1 simulates (FrameWriter.h).
    FrameWriter writer(scene, folder, !o.serialOutput);
    auto writeCheckpoint = [&](int f) {
        if (!checkpoints) return std::string();
        const std::string path = inFolder(out.checkpointFile, f);
        // Over several processes: a file per process and a manifest to resume from.
        if (distributed) return distributed->writeCheckpoint(path, *sim, fingerprint, f);
        vdbio::writeCheckpoint(path, sim->saveStates(), fingerprint, f);
        return path;
    };

    const std::uint64_t stepsAtStart = sim->stepCount();
    for (; frame <= last; ++frame) {
        const auto frameStart = Clock::now();
        const std::uint64_t stepsBefore = sim->stepCount();
        substep = 0;
        sim->beforeFrame(frame);
        advanceFrame(scene, *sim);

        const bool write = frame >= first;
        if (write && distributed) {
            FrameSnapshot snapshot = distributed->snapshot(out, *sim, frame);
            if (writes) writer.submit(std::move(snapshot));
        } else if (write) {
            writer.submit(snapshotFrame(out, *sim, frame));
        }
        if (stats) stats->flush();
        // Every process stops at the same frame, whichever saw the signal, and all report the
        // same one.
        const int stopSignal = distributed
                                   ? int(distributed->maxOf(double(StopSignals::received())))
                                   : StopSignals::received();
        std::string checkpoint;
        if (stopSignal != 0 || frame == last
            || (out.checkpointEvery > 0 && frame % out.checkpointEvery == 0)) {
            writer.finish(); // the frames on disk reach at least as far as the checkpoint
            checkpoint = writeCheckpoint(frame);
        }
        // Over several processes the counts are every process's, summed (collective).
        progress.frame(*sim, distributed ? distributed->counts(*sim) : sim->counts(), frame,
                       int(sim->stepCount() - stepsBefore), seconds(frameStart, Clock::now()),
                       write);
        emptyMedia.check(mediumCounts(*sim, distributed), frame);
        if (stopSignal != 0) {
            if (writes) {
                std::fprintf(stderr, "ghostfx: stopped by %s after frame %d%s\n",
                             StopSignals::describe(stopSignal), frame,
                             checkpoint.empty()
                                 ? " (no checkpoint: nothing to resume from)"
                                 : ("; resume with: "
                                    + resumeCommand(o, checkpoint,
                                                    distributed ? distributed->ranks() : 1))
                                       .c_str());
            }
            return StopSignals::exitCode(stopSignal);
        }
    }
    writer.finish();
    const double total = seconds(runStart, Clock::now());
    const std::uint64_t steps = sim->stepCount() - stepsAtStart;
    if (distributed) {
        const std::string counts = distributed->counts(*sim);
        progress.message(msg("done: ", steps, " steps in ", duration(total), " (",
                             total > 0 ? double(steps) / total : 0.0, " steps/s), ", counts));
        return 0;
    }
    progress.message(
        msg("done: ", steps, " steps in ", duration(total), " (",
            total > 0 ? double(steps) / total : 0.0, " steps/s), ", sim->particleCount(),
            " particles, ",
            sim->particleCount() ? double(sim->memoryBytes()) / double(sim->particleCount()) : 0.0,
            " bytes per particle"));
    return 0;
}

int runScene(const RunOptions& o)
{
    // Under mpirun: one simulation over the processes.
    const std::unique_ptr<DistributedRun> distributed = DistributedRun::startIfLaunched();
    if (!distributed) return runSceneWith(o, nullptr);
    try {
        return runSceneWith(o, distributed.get());
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
