/// @file   GasScene.h
/// @brief  Wiring of a scene to the gas solver: the keys of `settings.gas`, solids with their
///         motions and gas sources (beside LiquidScene.h for the liquid solver).
#pragma once

#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/sph/SolverState.h>
#include <ghostfx/vdbio/Scene.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ghostfx {
namespace cmd {

/// The gas methods by their scene names ("gas", "gas_ambient", "gas_uncorrected"): the values of
/// settings.method in a gas scene, and of settings.gas.method for a boiling scene's vapour.
const std::vector<std::pair<std::string, gas::Method>>& gasMethodNames();
/// The solver method of a scene name from gasMethodNames().
gas::Method gasMethod(const std::string& name);

/// Read the gas solver's settings from `g` (the scene's settings.gas, or an empty object) for
/// `method`; `defaultSpacing` is used where settings.gas.spacing is absent. Checks that no key
/// of `g` is left unread. Errors name the scene key.
gas::GasSettings gasSettings(const vdbio::Scene& scene, const vdbio::JsonObject& g,
                             double defaultSpacing, gas::Method method);

/// A gas solver set up for `scene`: solids (static or moving) and gas sources; with
/// `restored`, it continues from that state.
std::unique_ptr<gas::GasSolver> makeGasSolver(const vdbio::Scene& scene,
                                              const gas::GasSettings& settings,
                                              const sph::SolverState* restored);

/// Add one gas source to a gas solver, as makeGasSolver adds the scene's.
void addSceneGasSource(gas::GasSolver& solver, const vdbio::SceneGasSource& source);

} // namespace cmd
} // namespace ghostfx
