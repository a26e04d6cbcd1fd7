/// @file   LiquidScene.cc
#include "LiquidScene.h"

#include "StepSettings.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>

namespace ghostfx {
namespace cmd {

using ghost::GhostSettings;
using ghost::GhostSolver;
using sph::Real;
using sph::Vec3;

ghost::GhostSettings liquidSettings(const vdbio::Scene& scene, ghost::Method method)
{
    const vdbio::JsonObject& s = scene.settings;
    GhostSettings g;
    g.method = method;
    g.spacing = Real(scene.spacing);
    g.frameRate = Real(scene.frameRate);
    g.supportFactor = Real(s.inRange("kernel_support", g.supportFactor, 1.5, 5));
    g.restDensity = Real(s.positive("rest_density", g.restDensity));
    g.pressure = ghost::pressureFromName(s.choice("pressure", "tait", {"tait", "dfsph"}));
    if (g.pressure == ghost::PressureModel::Dfsph && method == ghost::Method::Basic) {
        s.failValue("pressure", "expected 'tait' with method 'basic' ([SB12]'s weakly "
                                "compressible baseline has no air for a pressure solve's free "
                                "surface)");
    }
    if (s.has("dfsph")) {
        const vdbio::JsonObject d = s.object("dfsph");
        ghost::DfsphSettings& o = g.dfsph;
        o.densityError = Real(d.inRange("density_error", o.densityError, 1e-7, 0.1));
        o.divergenceError = Real(d.inRange("divergence_error", o.divergenceError, 1e-7, 1));
        o.densityRelaxation = Real(d.inRange("density_relaxation", o.densityRelaxation, 1e-6, 1));
        o.maxIterations = int(d.inRange("max_iterations", o.maxIterations, 1, 100000));
        o.minTimeStep = Real(d.inRange("min_dt", o.minTimeStep, 1e-9, 1));
        o.maxTimeStep = Real(d.inRange("max_dt", o.maxTimeStep, 1e-9, 1));
        if (o.maxTimeStep < o.minTimeStep)
            d.failValue("max_dt",
                        "expected at least min_dt (" + std::to_string(o.minTimeStep) + " s)");
        o.warmStart = d.get<bool>("warm_start", o.warmStart);
        o.divergenceWarmStart = d.get<bool>("divergence_warm_start", o.divergenceWarmStart);
        o.keepGradients = d.get<bool>("keep_gradients", o.keepGradients);
        o.wallPressure = d.choice("wall_pressure", "mirror", {"mirror", "own"}) == "mirror"
                             ? ghost::DfsphSettings::WallPressure::Mirror
                             : ghost::DfsphSettings::WallPressure::Own;
        o.airDensity = d.choice("air_density", "full", {"full", "fill"}) == "fill"
                           ? ghost::DfsphSettings::AirDensity::Fill
                           : ghost::DfsphSettings::AirDensity::Full;
        o.airResampling = d.choice("air_resampling", "step", {"step", "time"}) == "time"
                              ? ghost::DfsphSettings::AirResampling::Time
                              : ghost::DfsphSettings::AirResampling::Step;
        constexpr double GiB = 1024.0 * 1024.0 * 1024.0;
        o.keptGradientLimit =
            GiB * d.inRange("kept_gradients_gb", o.keptGradientLimit / GiB, 0, 1e6);
        d.finish();
    }
    g.stiffness = Real(s.positive("stiffness", g.stiffness));
    const auto gravity =
        s.get<std::array<double, 3>>("gravity", {g.gravity[0], g.gravity[1], g.gravity[2]});
    g.gravity = Vec3(Real(gravity[0]), Real(gravity[1]), Real(gravity[2]));
    g.xsphEpsilon = Real(s.inRange("xsph_epsilon", g.xsphEpsilon, 0, 1));
    g.solidEpsilon = Real(s.inRange("solid_epsilon", g.solidEpsilon, 0, 1));
    // Absent: automatic (GhostSettings::relaxationPasses()).
    if (s.has("initial_relaxation")) {
        g.initialRelaxation = int(s.inRange("initial_relaxation", 0, 0, 1000));
        if (double(g.initialRelaxation) != s.get<double>("initial_relaxation", 0))
            s.failValue("initial_relaxation", "expected a whole number of passes, 0 to 1000");
    }
    // Absent: automatic (GhostSettings::shifting()).
    if (s.has("shifting")) g.shiftingCoefficient = Real(s.inRange("shifting", 0, 0, 20));
    g.solidSlip = s.choice("solid_slip", "free", {"free", "no_slip"}) == "free"
                      ? ghost::SolidSlip::Free
                      : ghost::SolidSlip::NoSlip;
    g.airResampleSteps = int(s.inRange("air_resample_steps", g.airResampleSteps, 1, 1000));
    g.airKeepFraction = Real(s.inRange("air_keep_fraction", g.airKeepFraction, 0, 10));
    g.airWeights =
        s.choice("air_weights", g.airWeights == ghost::AirWeights::Matched ? "matched" : "complete",
                 {"matched", "complete"})
                == "matched"
            ? ghost::AirWeights::Matched
            : ghost::AirWeights::Complete;
    g.basicXsphEpsilon = Real(s.inRange("basic_xsph_epsilon", g.basicXsphEpsilon, 0, 1));
    g.basicViscosityAlpha = Real(s.nonNegative("basic_viscosity_alpha", g.basicViscosityAlpha));
    g.lennardJonesStrength = Real(s.nonNegative("lennard_jones_strength", g.lennardJonesStrength));
    readStepSettings(s, g);
    g.tiledSampling = s.get<bool>("tiled_sampling", g.tiledSampling);
    using Relaxation = sph::PoissonSettings::Relaxation;
    const char* relaxation = g.samplingRelaxation == Relaxation::Packing ? "packing" : "sb12";
    g.samplingRelaxation =
        s.choice("sampling_relaxation", relaxation, {"sb12", "packing"}) == "packing"
            ? Relaxation::Packing
            : Relaxation::Sb12;
    g.killBox = scene.killBox;
    s.finish();
    g.validate();
    return g;
}

namespace {

/// The motion of a scene solid as the solver wants it.
ghost::RigidMotion motionOf(const vdbio::SceneSolid& solid)
{
    if (solid.motion.keys.empty()) {
        return sph::constantVelocity(Vec3(solid.velocity));
    }
    return solid.motion.motion();
}

} // namespace

namespace {

struct ProcessSampleCache
{
    std::mutex mutex;
    bool chosen = false;
    bool byDefault = false; ///< the per-user folder, not one the user named
    std::string folder;
    std::unique_ptr<vdbio::SampleCache> cache;
};

ProcessSampleCache& processCache()
{
    static ProcessSampleCache c;
    return c;
}

/// The default folder's size limit: $GHOSTFX_SAMPLE_CACHE_LIMIT_MB, else DEFAULT_LIMIT_MB.
std::uint64_t defaultSampleCacheLimit()
{
    constexpr std::uint64_t DEFAULT_LIMIT_MB = 2048;
    const char* env = std::getenv("GHOSTFX_SAMPLE_CACHE_LIMIT_MB");
    if (!env || !*env) return DEFAULT_LIMIT_MB << 20;
    char* end = nullptr;
    const unsigned long long mb = std::strtoull(env, &end, 10);
    if (*end != '\0' || mb == 0 || mb > (1ULL << 30) || env[0] == '-') {
        throw ValueError(msg("GHOSTFX_SAMPLE_CACHE_LIMIT_MB = '", env,
                             "': expected a whole number of MiB, at least 1"));
    }
    return std::uint64_t(mb) << 20;
}

} // namespace

bool isSampleCacheOff(const std::string& folder) { return folder.empty() || folder == "off"; }

std::string defaultSampleCacheFolder()
{
    namespace fs = std::filesystem;
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    // The XDG base directory specification: a relative XDG_CACHE_HOME is to be ignored.
    if (xdg && *xdg && fs::path(xdg).is_absolute())
        return (fs::path(xdg) / "ghostfx" / "samples").string();
    if (home && *home) return (fs::path(home) / ".cache" / "ghostfx" / "samples").string();
    return std::string();
}

vdbio::SampleCache* processSampleCacheIfMade()
{
    ProcessSampleCache& c = processCache();
    std::lock_guard<std::mutex> lock(c.mutex);
    return c.cache.get();
}

void setProcessSampleCache(const std::string& folder)
{
    ProcessSampleCache& c = processCache();
    std::lock_guard<std::mutex> lock(c.mutex);
    c.chosen = true;
    c.byDefault = false;
    c.folder = isSampleCacheOff(folder) ? std::string() : folder;
    c.cache.reset();
}

vdbio::SampleCache* processSampleCache()
{
    ProcessSampleCache& c = processCache();
    std::lock_guard<std::mutex> lock(c.mutex);
    if (!c.chosen) {
        const char* env = std::getenv("GHOSTFX_SAMPLE_CACHE");
        c.byDefault = env == nullptr;
        c.folder = c.byDefault             ? defaultSampleCacheFolder()
                   : isSampleCacheOff(env) ? std::string()
                                           : std::string(env);
        c.chosen = true;
    }
    if (c.cache || c.folder.empty()) return c.cache.get();
    if (!c.byDefault) {
        c.cache = std::make_unique<vdbio::SampleCache>(c.folder);
        return c.cache.get();
    }
    const std::uint64_t limit = defaultSampleCacheLimit();
    try {
        c.cache = std::make_unique<vdbio::SampleCache>(c.folder, limit);
    } catch (const IoError& e) {
        // Nobody asked for this folder: say why it is not used, once, and go on without.
        std::fprintf(stderr,
                     "ghostfx: warning: %s; running without a sample cache "
                     "(GHOSTFX_SAMPLE_CACHE=DIR chooses another folder, =off none)\n",
                     e.what());
        c.folder.clear();
    }
    return c.cache.get();
}

std::unique_ptr<GhostSolver> makeLiquidSolver(const vdbio::Scene& scene,
                                              const GhostSettings& settings,
                                              const sph::SolverState* restored)
{
    auto solver = std::make_unique<GhostSolver>(settings);
    solver->setSampleStore(processSampleCache());
    if (restored) solver->restoreState(*restored);
    for (const vdbio::SceneSolid& solid : scene.solids) {
        // A solid without motion keys moves at its constant velocity, or stands still: then its
        // particles are sorted once and never re-placed.
        if (solid.motion.keys.empty()) solver->addSolid(solid.shape, Vec3(solid.velocity));
        else solver->addMovingSolid(solid.shape, motionOf(solid));
    }
    if (!restored) {
        for (const vdbio::SceneLiquid& liquid : scene.liquids) {
            const std::size_t n = solver->addLiquid(liquid.shape, Vec3(liquid.velocity));
            if (n == 0) {
                throw SceneError(
                    msg("scene '", scene.file, "': liquid '", liquid.name, "' (", liquid.geometry,
                        ") gives no particles at spacing ", scene.spacing,
                        " m: it is empty, thinner than the spacing, or inside a solid"));
            }
        }
    }
    for (const vdbio::SceneEmitter& e : scene.emitters) {
        solver->addEmitter(e.shape, Vec3(e.velocity), e.start, e.end);
    }
    return solver;
}

void updateSolidSequences(const vdbio::Scene& scene, GhostSolver& solver, int frame)
{
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const vdbio::SceneSolid& solid = scene.solids[i];
        if (solid.sequenceFile.empty()) continue;
        const std::string file = vdbio::expandFramePattern(solid.sequenceFile, frame);
        solver.setSolidShape(
            i, vdbio::loadLevelSet(file, solid.sequenceGrid,
                                   msg("scene '", scene.file, "': solids[", i, "].sequence")));
    }
}

void checkSolidSequences(const vdbio::Scene& scene, int first, int last)
{
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const vdbio::SceneSolid& solid = scene.solids[i];
        if (solid.sequenceFile.empty()) continue;
        for (int f = first; f <= last; ++f) {
            const std::string file = vdbio::expandFramePattern(solid.sequenceFile, f);
            std::error_code ec;
            if (!std::filesystem::exists(file, ec)) {
                throw IoError(msg("scene '", scene.file, "': solids[", i, "].sequence: file '",
                                  file, "' does not exist (frames ", first, "-", last,
                                  " are needed)"));
            }
        }
    }
}

} // namespace cmd
} // namespace ghostfx
