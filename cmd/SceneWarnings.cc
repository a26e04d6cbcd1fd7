/// @file   SceneWarnings.cc
/// @brief  The warnings before the first step (SceneWarnings.h).
#include "SceneWarnings.h"

#include <ghostfx/sph/Exceptions.h>

#include <cmath>
#include <cstdio>

namespace ghostfx {
namespace cmd {

void warnFixedStepBeyondTheLimit(const vdbio::Scene& scene, const Simulation& sim)
{
    const double fixed = sim.fixedTimeStep();
    if (!(fixed > 0)) return;
    const double limit = sim.stabilityLimit();
    if (fixed <= limit) return;
    const int substeps = int(std::lround(1.0 / (fixed * scene.frameRate)));
    std::fprintf(stderr, "%s\n",
                 msg("ghostfx: warning: scene '", scene.file, "': the fixed step ", fixed,
                     " s (frame_rate ", scene.frameRate, ", substeps ", substeps, ") is ",
                     std::round(10 * fixed / limit) / 10, "x the stability limit ", limit,
                     " s (Courant number 1: sound speed and forces); expect a blow-up: use "
                     "substeps >= ",
                     int(std::ceil(substeps * fixed / limit)), ", or substeps 0 for CFL steps")
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
