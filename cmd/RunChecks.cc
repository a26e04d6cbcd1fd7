/// @file   RunChecks.cc
/// @brief  The checks and warnings before the first step (RunChecks.h).
#include "RunChecks.h"

#include <ghostfx/sph/Exceptions.h>

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace ghostfx {
namespace cmd {

std::string stepKeys(const vdbio::Scene& scene)
{
    const bool gas = scene.method.rfind("gas", 0) == 0, boiling = !scene.heaters.empty();
    std::string keys;
    if (!gas) keys = "settings.substeps, settings.cfl, settings.stiffness";
    if (gas || boiling) {
        keys += std::string(keys.empty() ? "" : "; ")
                + "settings.gas.substeps, settings.gas.cfl, settings.gas.kappa";
    }
    return keys;
}

void checkStepsPerFrame(const vdbio::Scene& scene, const Simulation& sim)
{
    if (sim.fixedTimeStep() > 0) return; // substeps are in range already
    const double step = sim.cflTimeStep();
    const double steps = 1.0 / (scene.frameRate * step);
    if (!(steps > MAX_STEPS_PER_FRAME)) return;
    throw SceneError(msg("scene '", scene.file, "': the CFL step at the start is ", step,
                         " s, ", steps, " steps a frame at settings.frame_rate ",
                         scene.frameRate, ", more than the ", MAX_STEPS_PER_FRAME,
                         " settings.substeps allows: expected a softer liquid or gas or a larger "
                         "step (",
                         stepKeys(scene), ")"));
}

void warnFixedStepBeyondTheLimit(const vdbio::Scene& scene, const Simulation& sim, bool prints)
{
    const double fixed = sim.fixedTimeStep();
    if (!(fixed > 0)) return;
    const double limit = sim.stabilityLimit();
    if (fixed <= limit || !prints) return;
    const int substeps = int(std::lround(1.0 / (fixed * scene.frameRate)));
    const double needed = std::ceil(substeps * fixed / limit);
    std::fprintf(stderr, "%s\n",
                 msg("ghostfx: warning: scene '", scene.file, "': the fixed step ", fixed,
                     " s (frame_rate ", scene.frameRate, ", substeps ", substeps, ") is ",
                     std::round(10 * fixed / limit) / 10, "x the stability limit ", limit,
                     " s (Courant number 1: sound speed and forces); expect a blow-up: ",
                     needed <= MAX_STEPS_PER_FRAME
                         ? msg("use substeps >= ", std::int64_t(needed),
                               ", or substeps 0 for CFL steps")
                         : msg("it would take ", needed, " substeps, more than the ",
                               MAX_STEPS_PER_FRAME, " allowed; lower the stiffness (",
                               stepKeys(scene), ")"))
                     .c_str());
}

void warnThinSolids(const vdbio::Scene& scene, double depth)
{
    if (!(depth > 0)) return;
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const vdbio::SceneSolid& solid = scene.solids[i];
        std::vector<const sph::LevelSet*> beside;
        if (solid.isStatic()) {
            for (std::size_t j = 0; j < scene.solids.size(); ++j) {
                if (j != i && scene.solids[j].isStatic()) beside.push_back(&scene.solids[j].shape);
            }
        }
        const double thin = solid.shape.fractionThinnerThan(sph::Real(depth), beside);
        if (thin < 0.01) continue;
        std::fprintf(stderr, "%s\n",
                     msg("ghostfx: warning: scene '", scene.file, "': solid '", solid.name,
                         "' is thinner than the kernel support ", depth, " m over ",
                         std::lround(100 * thin),
                         " % of the surface the liquid can reach: liquid there lacks boundary "
                         "particles (too low a density; a stiff liquid sticks to it); make it "
                         "at least ",
                         depth, " m thick")
                         .c_str());
    }
}

} // namespace cmd
} // namespace ghostfx
