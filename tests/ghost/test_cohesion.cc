/// @file   test_cohesion.cc
/// @brief  Cohesion to solids ([SB12] Sec. 3 "Solid Boundaries", Sec. 4.4, Figs. 1 and 11):
///         liquid resting against the underside of a ceiling stays attached with Ghost SPH
///         (ghost solid density from the liquid: no separation without air rushing in) and
///         falls away with Basic SPH (Lennard-Jones walls only repel).
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include "common/LiquidMeasures.h"
#include "common/Shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.01);

/// Drop (m) of the liquid's top layer (the highest 10 % of its particles) after 0.1 s.
double hangingDrop(Method method)
{
    GhostSettings s;
    s.method = method;
    s.spacing = H;
    s.seed = 4;
    // A stiffer liquid than the paper's (k = 2e4 Pa): the tension that holds the slab then
    // needs only a 0.3 % density deficit, so the slab hardly stretches. Ghost SPH takes the
    // fixed step of CFL 0.3 (dt = 1/4000 s). Basic SPH takes CFL steps with the force limit
    // (GhostSolver::stableTimeStep): its surface layer is flung at up to 35 m/s, far beyond
    // the Lennard-Jones strength D ~ 5 g H = 2 m^2/s^2, and at the fixed step 2 of 6 sample
    // realisations (seeds 4-9) drove a particle through the wall (an error); with the force
    // limit none did (505-536 steps, drops 5.8-6.9 cm).
    s.stiffness = Real(20000);
    s.frameRate = Real(30);
    s.substeps = method == Method::Ghost ? 133 : 0;
    GhostSolver solver(s);
    solver.addSolid(makeLevelSet(ghostfx::testing::invertedCupGrid(H), "cup"));
    // A 4 cm slab filling the top of the cup: hydrostatic tension at the top -rho0 g d =
    // -390 Pa, well within what the Tait equation holds (down to -k = -2000 Pa).
    solver.addLiquid(makeLevelSet(ghostfx::testing::ceilingSlabGrid(H), "slab"));
    auto topLayer = [&] { return ghostfx::testing::topLayerHeight(solver.particles()); };
    const double start = topLayer();
    for (int f = 0; f < 3; ++f) solver.advanceFrame(); // 0.1 s at 30 frames/s
    const double drop = start - topLayer();
    std::printf(
        "[measured] %s: top layer dropped %.4f m in %.2f s (free fall: %.4f m), %llu steps\n",
        methodName(method), drop, solver.time(), 0.5 * 9.81 * 0.1 * 0.1,
        static_cast<unsigned long long>(solver.stepCount()));
    return drop;
}

} // namespace

TEST(Cohesion, LiquidHangsUnderACeilingWithGhostSphAndFallsWithBasicSph)
{
    // Free fall drops the slab 4.9 cm in 0.1 s. Basic SPH: nothing holds the liquid to the
    // ceiling, its top layer falls away (measured 5.8-6.9 cm float over seeds 4-9: the walls'
    // Lennard-Jones repulsion pushes too); bound: more than 70 % of free fall.
    // Ghost SPH: the ghost solid takes the density of the liquid beneath it, so a gap opening
    // means tension that pulls the liquid back: the top layer stays at the ceiling (measured
    // 1.7-2.8 mm float over seeds 4-9, 0.5 mm double); bound: under 15 % of free fall (7 mm,
    // below a spacing). The slab's free lower surface does drip: a 4 cm layer of liquid
    // without surface tension is Rayleigh-Taylor unstable (growth time about 25 ms at 4 cm
    // wavelength), as real water of this size is, and how fast it drips depends on round-off
    // (float and double builds differ), so the test
    // watches the top layer. The cup's side walls keep air from entering along the ceiling.
    const double freeFall = 0.5 * 9.81 * 0.1 * 0.1;
    EXPECT_LT(hangingDrop(Method::Ghost), 0.15 * freeFall);
    EXPECT_GT(hangingDrop(Method::Basic), 0.7 * freeFall);
}
