/// @file   bench_plume.cc
/// @brief  A gas-only plume at [RYY15]'s vapour count: steps per second of the fast gas method
///         and of the ambient-air baseline on the same plume, with the per-phase breakdown.
/// @details The scene is `examples/gas_plume` (a 1.2 x 1.65 x 1.2 m kill box over a floor, a
///          burner sphere of radius 0.1 m emitting gas at 600 K and 0.4 m/s) at a finer spacing:
///          at 12.5 mm the plume settles at about 10k gas particles, the paper's boiling scene
///          has about 9k vapour particles and reports 67.3 steps per second (GTX 780).
///
///          1. fast: CFL steps until `--gas` visible gas particles exist (warm-up, not timed),
///             then `--steps` steps timed per phase;
///          2. ambient: a fresh baseline solver over the same kill box, floor and burner, holding
///             a copy of the fast plume; its first step fills the box with air (not timed), then
///             `--ambient-steps` steps at the fast run's last dt are timed.
///
///          Run: build/bench/bench_plume [--spacing 0.0125] [--gas 9000] [--steps 200]
#include "BenchMain.h"
#include "GasCopy.h"

#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>

#include <openvdb/openvdb.h>

#include <cstdio>

using namespace ghostfx;
using namespace ghostfx::sph;
using bench::now;

namespace {

/// The command line: the plume's spacing, the warm-up and the measured steps.
struct Options
{
    double spacing = 0.0125, maxWarmup = 3.0;
    int steps = 200, ambientSteps = 20;
    std::size_t gasTarget = 9000;
};

/// The command line into `o`.
void addOptions(CLI::App& app, Options& o)
{
    app.add_option("--spacing", o.spacing, "gas spacing (m)");
    app.add_option("--gas", o.gasTarget, "visible gas particles before the measurement");
    app.add_option("--max-warmup", o.maxWarmup, "most simulated warm-up time (s)");
    app.add_option("--steps", o.steps, "measured fast steps");
    app.add_option("--ambient-steps", o.ambientSteps, "measured baseline steps (0: skip)");
}

/// The plume's solid and source added to a solver.
void addScene(gas::GasSolver& solver, Real spacing)
{
    const Real band = spacing / 2;
    solver.addSolid(
        makeLevelSet(makeBoxLevelSet(Vec3(-0.6f, -0.15f, -0.6f), Vec3(0.6f, 0, 0.6f), band),
                     "floor"),
        Vec3(0));
    gas::GasSource burner;
    burner.temperature = Real(600);
    burner.velocity = Vec3(0, Real(0.4), 0);
    solver.addSource(
        makeLevelSet(makeSphereLevelSet(Vec3(0, Real(0.12), 0), Real(0.1), band), "burner"),
        burner);
}

void report(const char* name, const gas::GasSolver& g, int steps, double wall, Real dt)
{
    const gas::GasTimings& t = g.timings();
    const double per = 1000.0 / std::max<double>(1, double(t.steps));
    std::printf("%s: %d steps in %.3f s = %.1f steps/s (%.2f ms/step, dt %.3g s); gas %zu, "
                "ambient air %zu, mean gas neighbours %.0f\n",
                name, steps, wall, steps / wall, 1000 * wall / steps, double(dt),
                g.visibleGasCount(), g.ambientCount(), g.meanNeighbors());
    std::printf("  per step (ms): emission %.2f, neighbours %.2f, density %.2f, forces %.2f, "
                "integration %.2f\n",
                per * t.emission, per * t.neighbors, per * t.density, per * t.forces,
                per * t.integration);
}

/// The fast plume's warm-up and measured steps, then the ambient baseline's; prints both.
int run(const Options& o)
{
    openvdb::initialize();
    std::printf("bench_plume: %d threads, gas spacing %.4f m\n", parallel::maxThreads(), o.spacing);
    gas::GasSettings s;
    s.spacing = Real(o.spacing);
    s.seed = 1;
    s.frameRate = Real(30);
    s.domain = Aabb{Vec3(-0.6f, -0.05f, -0.6f), Vec3(0.6f, 1.6f, 0.6f)};

    double t0 = now();
    gas::GasSolver fast(s);
    addScene(fast, s.spacing);
    fast.step(fast.stableTimeStep()); // samples the floor and fills the burner
    std::printf("set-up (first step): %.2f s, gas boundary %zu\n", now() - t0,
                fast.particles().count(ParticleKind::Boundary));

    t0 = now();
    double warmTime = 0;
    int warm = 0;
    Real dt = 0;
    while (fast.visibleGasCount() < o.gasTarget && warmTime < o.maxWarmup) {
        dt = fast.stableTimeStep();
        fast.step(dt);
        warmTime += double(dt);
        ++warm;
    }
    std::printf("warm-up: %d steps, %.3f s simulated in %.1f s wall, gas %zu\n", warm, warmTime,
                now() - t0, fast.visibleGasCount());

    fast.resetTimings();
    t0 = now();
    for (int k = 0; k < o.steps; ++k) {
        dt = fast.stableTimeStep();
        fast.step(dt);
    }
    const double fastWall = now() - t0;
    report("fast", fast, o.steps, fastWall, dt);
    if (o.ambientSteps <= 0) return 0;

    gas::GasSettings bs = s;
    bs.method = gas::Method::Ambient;
    gas::GasSolver ambient(bs);
    addScene(ambient, s.spacing);
    bench::copyGas(fast, ambient);
    t0 = now();
    ambient.step(dt); // fills the box with air (not timed)
    std::printf("ambient set-up step (air fill): %.1f s, air %zu\n", now() - t0,
                ambient.ambientCount());
    ambient.resetTimings();
    t0 = now();
    for (int k = 0; k < o.ambientSteps; ++k) ambient.step(dt);
    const double ambientWall = now() - t0;
    report("ambient", ambient, o.ambientSteps, ambientWall, dt);
    std::printf("ratio: fast %.1f steps/s / ambient %.1f steps/s = %.1fx per step\n",
                o.steps / fastWall, o.ambientSteps / ambientWall,
                (ambientWall / o.ambientSteps) / (fastWall / o.steps));
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    return bench::benchMain(argc, argv, "bench_plume",
                            "bench_plume: gas-only plume, fast gas vs the ambient-air baseline",
                            addOptions, run);
}
