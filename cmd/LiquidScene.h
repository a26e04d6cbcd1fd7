/// @file   LiquidScene.h
/// @brief  Wiring of a scene to the liquid solver: the liquid keys of `settings`, solids with
///         their motions, liquid bodies and emitters.
#pragma once

#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/SolverState.h>
#include <ghostfx/vdbio/SampleCache.h>
#include <ghostfx/vdbio/Scene.h>

#include <memory>

namespace ghostfx {
namespace cmd {

/// Read the liquid solver's settings for `method` from `scene.settings` (and the shared ones
/// already read), then check that no key of `settings` is left unread. Errors name the scene key.
ghost::GhostSettings liquidSettings(const vdbio::Scene& scene, ghost::Method method);

/// The JSON pointers of the scene keys a resumed run may change ("/settings/max_speed"): the
/// rows of the liquid, DFSPH, gas and phase-transition tables that a checkpoint need not match.
std::vector<std::string> settingsFreeOnResume();

/// What a checkpoint of `scene` carries and a resume compares: the scene's simulation
/// fingerprint without the keys of settingsFreeOnResume().
std::string checkpointFingerprint(const vdbio::Scene& scene);

/// A liquid solver set up for `scene`: solids (static, moving or keyed), liquid bodies,
/// emitters. With `restored`, the solver continues from that state: liquid bodies are not
/// sampled again and solids take over their restored ghosts.
std::unique_ptr<ghost::GhostSolver> makeLiquidSolver(const vdbio::Scene& scene,
                                                     const ghost::GhostSettings& settings,
                                                     const sph::SolverState* restored = nullptr);

/// Add one solid (static, moving at its velocity, keyed, or dynamic) or one emitter to a liquid solver,
/// as makeLiquidSolver adds the scene's.
void addSceneSolid(ghost::GhostSolver& solver, const vdbio::SceneSolid& solid);
void addSceneEmitter(ghost::GhostSolver& solver, const vdbio::SceneEmitter& emitter);
/// Sample one of `scene`'s liquid bodies into a liquid solver with its velocity and its own
/// viscosity, if it has one; returns the particles added. A bad value is a SceneError naming
/// the scene and the liquid.
std::size_t addSceneLiquid(ghost::GhostSolver& solver, const vdbio::Scene& scene,
                           const vdbio::SceneLiquid& liquid);

/// Refuse a scene with a dynamic solid where the solvers cannot move one (`why` names them:
/// "a gas scene"): a SceneError naming the solid's key.
void refuseDynamicSolids(const vdbio::Scene& scene, const std::string& why);

/// This process's sample cache (vdbio::SampleCache): the folder of `--sample-cache`, else of
/// $GHOSTFX_SAMPLE_CACHE, else the per-user defaultSampleCacheFolder(); "off" (or empty) in
/// either place: none (null). Liquid solvers made by makeLiquidSolver take their solids' and
/// liquid bodies' samples from it, as SPlisHSPlasH keeps its boundary volume maps: a scene run
/// again skips sampling its unchanged shapes, with the same results bit for bit. Made on
/// first use. A folder the user named that cannot be written is an IoError naming it; the
/// default folder then gives a warning and the run goes on without a cache. The default
/// folder is kept within $GHOSTFX_SAMPLE_CACHE_LIMIT_MB (default 2048) MiB, least recently
/// used shapes removed first; a named folder is the user's and is never trimmed.
vdbio::SampleCache* processSampleCache();
/// The cache processSampleCache() has made, or null: asks nothing and makes no folder.
vdbio::SampleCache* processSampleCacheIfMade();
/// Use `folder` ("off" or empty: none, and not the environment's either) from now on.
void setProcessSampleCache(const std::string& folder);
/// $XDG_CACHE_HOME/ghostfx/samples, else $HOME/.cache/ghostfx/samples; empty without either.
std::string defaultSampleCacheFolder();
/// Whether a folder given for the sample cache means none: "off" or empty.
bool isSampleCacheOff(const std::string& folder);

/// Before simulating towards `frame` (the state at t = frame / fps), give every solid with a
/// per-frame file sequence that frame's shape.
void updateSolidSequences(const vdbio::Scene& scene, ghost::GhostSolver& solver, int frame);

/// Check, before simulating, that every per-frame solid file from `first` to `last` exists, so a
/// missing frame stops the run at once instead of midway.
void checkSolidSequences(const vdbio::Scene& scene, int first, int last);

} // namespace cmd
} // namespace ghostfx
