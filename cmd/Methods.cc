/// @file   Methods.cc
/// @brief  The method registry, and the scene rules that follow from a method's medium.
#include "Methods.h"

#include "GasScene.h"
#include "SimulationParts.h"

#include <ghostfx/sph/Exceptions.h>

#include <type_traits>

namespace ghostfx {
namespace cmd {

namespace {

using Restored = std::vector<sph::SolverState>;

const sph::SolverState* first(const Restored* restored)
{
    return restored && !restored->empty() ? &restored->front() : nullptr;
}

/// An entry whose simulation is `make(scene, solverMethod, states)` and whose check is
/// `check(scene, solverMethod)`.
template <typename SolverMethod, typename Restore>
Method entry(std::string name, Medium medium, std::string baselineOf, std::string summary,
             SolverMethod m, void (*check)(const vdbio::Scene&, SolverMethod),
             std::unique_ptr<Simulation> (*make)(const vdbio::Scene&, SolverMethod, Restore))
{
    Method method{std::move(name), medium, std::move(baselineOf), std::move(summary), {}, {}};
    method.check = [m, check](const vdbio::Scene& scene) { check(scene, m); };
    method.make = [m, make](const vdbio::Scene& scene, const Restored* restored) {
        if constexpr (std::is_same_v<Restore, const Restored*>) return make(scene, m, restored);
        else return make(scene, m, first(restored));
    };
    return method;
}

/// A liquid method of libghost ([SB12]); with heaters it boils (BoilingSimulation).
Method liquidMethod(ghost::Method m, std::string baselineOf, std::string summary)
{
    return entry(ghost::methodName(m), Medium::Liquid, std::move(baselineOf), std::move(summary), m,
                 &checkLiquidSimulation, &makeLiquidSimulation);
}

/// A gas method of libgas ([RYY15]), named as in gasMethodNames().
Method gasSolverMethod(const std::string& name, std::string baselineOf, std::string summary)
{
    return entry(name, Medium::Gas, std::move(baselineOf), std::move(summary), gasMethod(name),
                 &checkGasSimulation, &makeGasSimulation);
}

/// The entries of `scene` that its medium cannot simulate, refused with the key that holds them.
void checkMedium(const vdbio::Scene& scene, const Method& method)
{
    const vdbio::JsonObject root(scene.document, scene.document.get(), "", scene.file);
    const bool gas = method.medium == Medium::Gas;
    const bool boiling = !gas && !scene.heaters.empty();
    // Per-frame shapes are applied by the liquid solver only; a gas (or a boiling liquid's
    // vapour) would keep the first shape while the scene says it deforms.
    if (gas || boiling) {
        for (std::size_t i = 0; i < scene.solids.size(); ++i) {
            if (scene.solids[i].sequenceFile.empty()) continue;
            root.fail(msg("solids[", i, "].sequence"),
                      msg("solid '", scene.solids[i].name,
                          "' deforms per frame, which only a liquid scene supports; ",
                          gas ? "a gas" : "a boiling",
                          " scene takes static or rigidly moving solids ('velocity' or 'motion')"));
        }
    }
    if ((gas || boiling) && !scene.outputs.whitewaterFile.empty()) {
        root.fail("outputs.whitewater",
                  msg("whitewater is made from a liquid's splashes in liquid scenes; this ",
                      gas ? "gas" : "boiling", " scene makes none (switch outputs.whitewater "
                      "off)"));
    }
    if (gas) {
        if (!scene.liquids.empty() || !scene.emitters.empty() || !scene.heaters.empty()) {
            root.fail(scene.liquids.empty() ? (scene.emitters.empty() ? "heaters" : "emitters")
                                            : "liquids",
                      msg("a '", method.name,
                          "' scene simulates gas only: liquids, emitters and heaters need a "
                          "liquid method ('ghost' or 'basic'; with heaters, the liquid boils "
                          "into gas)"));
        }
        if (scene.gasSources.empty()) {
            root.fail("gas_sources", "the scene has no gas: expected at least one gas source");
        }
        return;
    }
    if (scene.liquids.empty() && scene.emitters.empty()) {
        root.fail("liquids",
                  "the scene has no liquid: expected at least one liquid body or emitter");
    }
    if (!boiling) {
        if (!scene.gasSources.empty()) {
            root.fail("gas_sources",
                      "gas sources need a gas method (settings.method 'gas', 'gas_ambient' or "
                      "'gas_uncorrected') or heaters, for boiling");
        }
        if (!scene.forceFields.empty()) {
            root.fail("force_fields",
                      "attractors act on gas; this scene has no gas (expected a gas method in "
                      "settings.method, or heaters that boil the liquid into vapour)");
        }
        if (scene.settings.has("gas")) {
            scene.settings.fail("gas", "gas settings need a gas method or heaters (boiling)");
        }
    }
}

} // namespace

const std::vector<Method>& methods()
{
    static const std::vector<Method> all = {
        liquidMethod(ghost::Method::Ghost, "",
                     "Ghost SPH [SB12]: ghost air around the liquid, ghost solids in the walls"),
        liquidMethod(ghost::Method::Basic, "ghost",
                     "Basic SPH, the [SB12] baseline: no ghosts, boundary particles in the walls"),
        gasSolverMethod("gas", "",
                        "fast gas [RYY15]: no ambient air, density and force compensation"),
        gasSolverMethod("gas_ambient", "gas",
                        "the [RYY15] standard baseline: domain.kill_box filled with ambient air"),
        gasSolverMethod("gas_uncorrected", "gas",
                        "the [RYY15] Fig. 4c ablation: no ambient air and no compensation"),
    };
    return all;
}

std::string methodNames()
{
    const std::vector<Method>& all = methods();
    std::string names;
    for (std::size_t i = 0; i < all.size(); ++i) {
        if (i > 0) names += i + 1 == all.size() ? " or " : ", ";
        names += "'" + all[i].name + "'";
    }
    return names;
}

const Method& methodOf(const vdbio::Scene& scene)
{
    for (const Method& m : methods()) {
        if (m.name != scene.method) continue;
        checkMedium(scene, m);
        return m;
    }
    std::vector<std::string> names;
    for (const Method& m : methods()) names.push_back(m.name);
    const std::string near = vdbio::closestKey(scene.method, names);
    scene.settings.failValue("method",
                             "expected " + methodNames()
                                 + (near.empty() ? "" : " (did you mean '" + near + "'?)"));
}

} // namespace cmd
} // namespace ghostfx
