/// @file   GasScene.cc
#include "GasScene.h"

#include "LiquidScene.h"
#include "SettingReader.h"

#include <ghostfx/sph/Exceptions.h>

namespace ghostfx {
namespace cmd {

using sph::Real;
using sph::Vec3;

/// The gas keys of the scene: settings.gas { ... }.
const std::vector<std::pair<std::string, gas::Method>>& gasMethodNames()
{
    static const std::vector<std::pair<std::string, gas::Method>> names = {
        {"gas", gas::Method::Fast},
        {"gas_ambient", gas::Method::Ambient},
        {"gas_uncorrected", gas::Method::Uncorrected}};
    return names;
}

gas::Method gasMethod(const std::string& name)
{
    for (const auto& [n, m] : gasMethodNames()) {
        if (n == name) return m;
    }
    throw ValueError(
        msg("gas method '", name, "': expected 'gas', 'gas_ambient' or 'gas_uncorrected'"));
}

gas::GasSettings gasSettings(const vdbio::Scene& scene, const vdbio::JsonObject& g,
                             double defaultSpacing, gas::Method method)
{
    refuseDynamicSolids(scene, scene.heaters.empty() ? "a gas scene"
                                                     : "a boiling scene (its vapour's gas solver)");
    gas::GasSettings s;
    if (g.has("variant")) {
        // The gas baselines are methods now, chosen like the liquid's (settings.method).
        g.fail("variant",
               "replaced by the method: settings.method 'gas' (fast), 'gas_ambient' "
               "or 'gas_uncorrected' (for a boiling scene's vapour: settings.gas.method)");
    }
    s.method = method;
    s.spacing = Real(defaultSpacing);
    readSettingTable(g, gas::gasSettingTable(), s);
    s.frameRate = Real(scene.frameRate);
    s.domain = scene.killBox;
    // force_fields ([RYY15] Fig. 7): point attractors act on the gas.
    for (const vdbio::SceneForceField& field : scene.forceFields) {
        gas::Attractor a;
        a.position = Vec3(field.attractor.position);
        a.strength = Real(field.attractor.strength);
        a.radius = Real(field.attractor.radius);
        a.falloff = gas::falloffFromName(field.attractor.falloff);
        s.attractors.push_back(a);
    }
    g.finish();
    if (s.method == gas::Method::Ambient && s.domain.empty()) {
        const char* what =
            "the ambient-air baseline fills a box with air: expected domain.kill_box";
        if (g.has("method")) g.failValue("method", what);
        scene.settings.failValue("method", what);
    }
    validateSceneSettings(scene.file, s);
    return s;
}

std::unique_ptr<gas::GasSolver> makeGasSolver(const vdbio::Scene& scene,
                                              const gas::GasSettings& settings,
                                              const sph::SolverState* restored)
{
    auto solver = std::make_unique<gas::GasSolver>(settings);
    if (restored) solver->restoreState(*restored);
    for (const vdbio::SceneSolid& solid : scene.solids) {
        if (solid.motion.keys.empty()) solver->addSolid(solid.shape, Vec3(solid.velocity));
        else solver->addMovingSolid(solid.shape, solid.motion.motion());
    }
    for (const vdbio::SceneGasSource& src : scene.gasSources) addSceneGasSource(*solver, src);
    return solver;
}

void addSceneGasSource(gas::GasSolver& solver, const vdbio::SceneGasSource& src)
{
    gas::GasSource s;
    s.temperature = Real(src.temperature);
    s.velocity = Vec3(src.velocity);
    s.rate = Real(src.rate);
    s.start = src.start;
    s.end = src.end;
    if (!src.motion.keys.empty()) s.motion = src.motion.motion();
    solver.addSource(src.shape, s);
}

} // namespace cmd
} // namespace ghostfx
