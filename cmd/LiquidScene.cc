/// @file   LiquidScene.cc
#include "LiquidScene.h"

#include "SettingReader.h"

#include <ghostfx/gas/PhaseTransition.h>

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
    readSettingTable(s, ghost::liquidSettingTable(), g);
    if (s.has("dfsph")) {
        const vdbio::JsonObject d = s.object("dfsph");
        readSettingTable(d, ghost::dfsphSettingTable(), g.dfsph);
        d.finish();
    }
    g.killBox = scene.killBox;
    // settings.whitewater: read by whitewaterSettings (SceneWhitewater.h); boiling scenes make
    // no whitewater, so theirs stays an unknown key.
    if (scene.heaters.empty()) s.has("whitewater");
    s.finish();
    validateSceneSettings(scene.file, g);
    if (g.method != ghost::Method::Ghost) {
        refuseDynamicSolids(scene, msg("settings.method '", ghost::methodName(g.method), "'"));
    }
    return g;
}

std::vector<std::string> settingsFreeOnResume()
{
    std::vector<std::string> pointers;
    addFreeOnResume(ghost::liquidSettingTable(), "/settings", pointers);
    addFreeOnResume(ghost::dfsphSettingTable(), "/settings/dfsph", pointers);
    addFreeOnResume(gas::gasSettingTable(), "/settings/gas", pointers);
    addFreeOnResume(gas::phaseSettingTable(), "/phase_transition", pointers);
    return pointers;
}

std::string checkpointFingerprint(const vdbio::Scene& scene)
{
    return scene.simulationFingerprint(settingsFreeOnResume());
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

/// A liquid's or an emitter's own viscosity, checked: a SceneError names the scene and it.
template <typename Entry>
std::optional<Real> ownViscosity(const vdbio::Scene& scene, const char* what, const Entry& e)
{
    if (!e.viscosity) return std::nullopt;
    try {
        ghost::checkOwnViscosity(Real(*e.viscosity), msg(what, " '", e.name, "'"));
    } catch (const ValueError& error) {
        throw SceneError(msg("scene '", scene.file, "': ", error.what()));
    }
    return Real(*e.viscosity);
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
    // Each liquid's and emitter's own viscosity is checked before anything is sampled.
    for (const vdbio::SceneLiquid& l : scene.liquids) ownViscosity(scene, "liquid", l);
    for (const vdbio::SceneEmitter& e : scene.emitters) ownViscosity(scene, "emitter", e);
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const vdbio::SceneSolid& solid = scene.solids[i];
        try {
            addSceneSolid(*solver, solid);
        } catch (const ValueError& e) {
            throw SceneError(
                msg("scene '", scene.file, "': solids[", i, "] '", solid.name, "': ", e.what()));
        }
    }
    if (!restored) {
        for (const vdbio::SceneLiquid& liquid : scene.liquids) {
            const std::size_t n = addSceneLiquid(*solver, scene, liquid);
            if (n == 0) {
                throw SceneError(
                    msg("scene '", scene.file, "': liquid '", liquid.name, "' (", liquid.geometry,
                        ") gives no particles at spacing ", scene.spacing,
                        " m: it is empty, thinner than the spacing, or inside a solid"));
            }
        }
    }
    for (const vdbio::SceneEmitter& e : scene.emitters) addSceneEmitter(*solver, e);
    return solver;
}

std::size_t addSceneLiquid(GhostSolver& solver, const vdbio::Scene& scene,
                           const vdbio::SceneLiquid& liquid)
{
    const std::optional<Real> viscosity = ownViscosity(scene, "liquid", liquid);
    return solver.addLiquid(liquid.shape, Vec3(liquid.velocity), viscosity);
}

void addSceneSolid(GhostSolver& solver, const vdbio::SceneSolid& solid)
{
    if (solid.dynamic) {
        const vdbio::SceneDynamic& d = *solid.dynamic;
        ghost::DynamicSolid body;
        body.density = d.density;
        body.mass = d.mass;
        body.velocity = d.velocity;
        body.angularVelocity = d.angularVelocity;
        body.material.restitution = d.restitution;
        body.material.friction = d.friction;
        solver.addDynamicSolid(solid.shape, body);
        return;
    }
    // A solid without motion keys moves at its constant velocity, or stands still: then its
    // particles are sorted once and never re-placed.
    if (solid.motion.keys.empty()) solver.addSolid(solid.shape, Vec3(solid.velocity));
    else solver.addMovingSolid(solid.shape, motionOf(solid));
}

void addSceneEmitter(GhostSolver& solver, const vdbio::SceneEmitter& emitter)
{
    const Vec3 velocity(emitter.velocity);
    const std::optional<Real> viscosity =
        emitter.viscosity ? std::optional<Real>(Real(*emitter.viscosity)) : std::nullopt;
    if (emitter.motion.keys.empty()) {
        solver.addEmitter(emitter.shape, velocity, emitter.start, emitter.end, viscosity);
    } else {
        solver.addMovingEmitter(emitter.shape, velocity, emitter.motion.motion(), emitter.start,
                                emitter.end, viscosity);
    }
}

void refuseDynamicSolids(const vdbio::Scene& scene, const std::string& why)
{
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        if (!scene.solids[i].dynamic) continue;
        throw SceneError(msg("scene '", scene.file, "': solids[", i, "].dynamic: solid '",
                             scene.solids[i].name, "' is dynamic, which ", why,
                             " cannot simulate: expected a solid without 'dynamic'"));
    }
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
