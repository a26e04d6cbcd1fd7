/// @file   Methods.h
/// @brief  The registry of simulation methods: one entry per value of a scene's
///         `settings.method`, holding everything the program knows about that method.
/// @details A method names its medium (liquid or gas), what it is a baseline of, a line for
///          messages and docs, and two functions: one that reads and checks its scene keys
///          without sampling a particle, and one that builds the Simulation. The frame loop,
///          outputs, checkpoints, studies and the Python module only see the entry; the scene
///          reader (vdbio) only reads the name. docs/architecture.md shows how to add one.
#pragma once

#include "Simulation.h"

#include <ghostfx/sph/SolverState.h>
#include <ghostfx/vdbio/Scene.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ghostfx {
namespace cmd {

/// What a method simulates; it decides which scene entries make sense (a gas method takes gas
/// sources and no liquid; a liquid method takes liquids, emitters and heaters that boil it).
enum class Medium { Liquid, Gas };

struct Method
{
    std::string name;       ///< the scene's settings.method
    Medium medium;          ///< what it simulates
    std::string baselineOf; ///< the method this one is a comparison baseline for ("": none)
    std::string summary;    ///< one line: what it is and where it comes from

    /// Read and check the method's settings keys of `scene` (every key read, none left over),
    /// as `make` will, without building a solver.
    std::function<void(const vdbio::Scene& scene)> check;
    /// The simulation of `scene`, fresh (`restored` null) or continuing from saved states.
    std::function<std::unique_ptr<Simulation>(const vdbio::Scene& scene,
                                              const std::vector<sph::SolverState>* restored)>
        make;
};

/// Every method, in the order messages and docs list them.
const std::vector<Method>& methods();

/// The entry for `scene.method`, after checking that the scene's entries fit its medium.
/// Throws SceneError naming settings.method (with the known names) or the misplaced entry.
const Method& methodOf(const vdbio::Scene& scene);

/// "ghost, basic, gas, gas_ambient or gas_uncorrected".
std::string methodNames();

} // namespace cmd
} // namespace ghostfx
