/// @file   bench_gas.cc
/// @brief  Boiling scene of [RYY15] Fig. 4 at the paper's scale: a Ghost SPH liquid [SB12] of about
///         40k particles in a heated pan coupled to the gas through gas::PhaseTransition, with
///         about 9k vapour particles; steps per second of the fast gas method (Fig. 4a) and of
///         the ambient-air baseline (Fig. 4b) in the same run, with the per-phase breakdown.
/// @details Scene: an open-top pan (inside 2a x 2a, walls 4 h thick), water of depth d at
///          liquid spacing h, at the boiling point; the pan's bottom plate heats the water at
///          `--heater` K. The vapour's rest density is 1/1000 of the water's ([RYY15] Sec. 6);
///          its spacing is h (1000 / 12)^(1/3), so a boiling daughter (1/12 of a liquid
///          particle) has the gas reference mass. Warm-up: coupled steps until `--vapour`
///          vapour particles exist (or `--max-warmup` steps), not timed. Then:
///           1. fast: `--steps` coupled steps, timed per phase (liquid, heat, transition,
///              boundary, gas);
///           2. baseline: the same liquid continues with a fresh ambient-air gas solver whose
///              domain box (`--domain` m wide and deep, `--height` m high above the pan) is
///              filled with air at the vapour spacing; the current vapour is copied into it;
///              `--baseline-steps` coupled steps, timed the same way. The air fill happens in
///              the first baseline step, which is not timed.
///          dt = 1 / 1200 s (the [SB12] stiffness at 5 mm needs it; [RYY15] ran 2 steps per 1/60
///          s frame with its own liquid). Plain main: one run takes minutes.
///
///          Run: build/bench/bench_gas [--spacing 0.005] [--steps 20] [--baseline-steps 3]
#include "GhostLiquidSide.h"

#include "BenchMain.h"
#include "GasCopy.h"

#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/gas/PhaseTransition.h>
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>

#include <openvdb/openvdb.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <memory>

using namespace ghostfx;
using namespace ghostfx::sph;
using bench::now;

namespace {

/// The command line: the pan and its water, the heater, the warm-up, the measured steps and
/// the baseline's air box.
struct Options
{
    double spacing = 0.005, halfWidth = 0.1, depth = 0.17, heater = 393.15;
    double domain = 1.6, height = 2.4;
    int steps = 20, baselineSteps = 3, maxWarmup = 400;
    std::size_t vapourTarget = 9000;
    std::string turbulence = "auto"; ///< the fast gas's (the baseline has none)
};

void report(const char* name, const gas::PhaseTransition& c, const gas::GasSolver& g, double wall,
            int steps, std::size_t liquid)
{
    const auto& t = c.timings();
    const double per = 1000.0 / std::max<double>(1, double(t.steps));
    std::printf("%s: %d steps in %.2f s = %.2f steps/s (%.1f ms/step); liquid %zu, vapour %zu, "
                "ambient air %zu, gas boundary %zu\n",
                name, steps, wall, steps / wall, 1000 * wall / steps, liquid, g.visibleGasCount(),
                g.ambientCount(), c.boundaryCount());
    std::printf("  per step (ms): liquid %.1f, heat %.1f, transition %.1f, boundary %.1f, gas %.1f "
                "(gas: neighbours %.1f, density %.1f, forces %.1f, integration %.1f)\n",
                per * t.liquid, per * t.heat, per * t.transition, per * t.boundary, per * t.gas,
                1000 * g.timings().neighbors / std::max<double>(1, double(g.timings().steps)),
                1000 * g.timings().density / std::max<double>(1, double(g.timings().steps)),
                1000 * g.timings().forces / std::max<double>(1, double(g.timings().steps)),
                1000 * g.timings().integration / std::max<double>(1, double(g.timings().steps)));
    std::printf("  gas-only rate: %.2f steps/s; mean gas neighbours %.0f\n",
                double(t.steps) / t.gas, g.meanNeighbors());
}

/// The open-top pan (walls 4 h thick) as the liquid's solid and the water in it; prints the
/// sampling time.
void addPanAndWater(ghost::GhostSolver& liquid, const Options& o)
{
    const Real H = Real(o.spacing), a = Real(o.halfWidth);
    const double wall = 4 * double(H);
    const openvdb::Vec3d lo(-a - wall, -wall, -a - wall), hi(a + wall, 2 * o.depth, a + wall);
    const openvdb::Vec3d ilo(-a, 0, -a), ihi(a, 4 * o.depth, a);
    auto sdf = [&](const openvdb::Vec3d& x) {
        return std::max(boxSignedDistance(x, lo, hi), -boxSignedDistance(x, ilo, ihi));
    };
    const Aabb panBox{Vec3(Real(lo.x()), Real(lo.y()), Real(lo.z())),
                      Vec3(Real(hi.x()), Real(hi.y()), Real(hi.z()))};
    const double t0 = now();
    liquid.addSolid(makeLevelSet(levelSetFromSdf(sdf, panBox, H / 2), "pan"));
    liquid.addLiquid(
        makeLevelSet(makeBoxLevelSet(Vec3(-a, 0, -a), Vec3(a, Real(o.depth), a), H / 2), "water"));
    std::printf("set-up (sampling): %.1f s, %zu liquid particles\n", now() - t0,
                liquid.count(ParticleKind::Liquid));
}

/// The phase transition of the scene: water at the boiling point, liquid spacing `H` (m).
gas::PhaseSettings phaseSettings(Real H)
{
    gas::PhaseSettings ps;
    ps.initialTemperature = ps.boilingPoint;
    ps.latentHeat = Real(20);
    ps.heatingTime = Real(0.05);
    ps.heaterBand = Real(1.5) * H;
    ps.evaporationRate = Real(0.5);
    return ps;
}

/// The pan's bottom plate, the heater: half width `a` (m), liquid spacing `H` (m).
LevelSet heaterPlate(Real a, Real H)
{
    return makeLevelSet(makeBoxLevelSet(Vec3(-a - 4 * H, -4 * H, -a - 4 * H),
                                        Vec3(a + 4 * H, 0, a + 4 * H), H / 2, Real(8)),
                        "plate");
}

/// Coupled steps of `dt` (s) until `--vapour` vapour particles exist or `--max-warmup` steps
/// have run (not timed); prints the counts.
void warmUp(gas::PhaseTransition& fast, const gas::GasSolver& fastGas, const Options& o, Real dt)
{
    const double t0 = now();
    int warm = 0;
    while (warm < o.maxWarmup && fastGas.visibleGasCount() < o.vapourTarget) {
        fast.step(dt);
        ++warm;
    }
    std::printf("warm-up: %d steps in %.1f s, vapour %zu, boiled %zu, evaporated %zu\n", warm,
                now() - t0, fastGas.visibleGasCount(), fast.boiledCount(), fast.evaporatedCount());
}

/// The ambient baseline: the same liquid, a fresh ambient-air gas solver holding a copy of the
/// vapour; its first step fills the air box (not timed), then `--baseline-steps` timed steps.
/// Returns their wall time (s).
double timeBaseline(gas::PhaseTransition& baseline, gas::GasSolver& ambientGas,
                    const ghost::GhostSolver& liquid, const Options& o, Real dt)
{
    double t0 = now();
    baseline.step(dt); // fills the air box (not timed)
    std::printf("baseline set-up step (air fill): %.1f s, air %zu\n", now() - t0,
                ambientGas.ambientCount());
    baseline.resetTimings();
    ambientGas.resetTimings();
    t0 = now();
    for (int k = 0; k < o.baselineSteps; ++k) baseline.step(dt);
    const double baseWall = now() - t0;
    report("ambient baseline", baseline, ambientGas, baseWall, o.baselineSteps,
           liquid.count(ParticleKind::Liquid));
    return baseWall;
}

/// Set up the pan, warm up and time the fast gas, then the ambient baseline; prints both.
int run(const Options& o)
{
    openvdb::initialize();
    const Real H = Real(o.spacing), a = Real(o.halfWidth);
    const Real dt = Real(1) / Real(1200);
    std::printf("bench_gas: %d threads, liquid spacing %.4f m, pan %.2f x %.2f m, depth %.3f m\n",
                parallel::maxThreads(), o.spacing, 2 * o.halfWidth, 2 * o.halfWidth, o.depth);

    ghost::GhostSettings ls;
    ls.spacing = H;
    ls.seed = 5;
    ghost::GhostSolver liquid(ls);
    addPanAndWater(liquid, o);
    coupling::GhostLiquidSide side(liquid);

    gas::GasSettings gs;
    gs.spacing = H * Real(std::cbrt(1000.0 / 12.0));
    gs.restDensity = Real(1);
    gs.seed = 7;
    gs.turbulence = gas::turbulenceFromName(o.turbulence);
    gas::GasSolver fastGas(gs);
    const gas::PhaseSettings ps = phaseSettings(H);
    const LevelSet plate = heaterPlate(a, H);
    gas::PhaseTransition fast(fastGas, side, ps);
    fast.addHeater(plate, Real(o.heater));
    warmUp(fast, fastGas, o, dt);

    fast.resetTimings();
    fastGas.resetTimings();
    liquid.resetTimings();
    const double t0 = now();
    for (int k = 0; k < o.steps; ++k) fast.step(dt);
    const double fastWall = now() - t0;
    report("fast", fast, fastGas, fastWall, o.steps, liquid.count(ParticleKind::Liquid));
    const gas::MassBudget mb = fast.massBudget();
    std::printf("  mass budget: liquid %.6e + gas %.6e + removed %.3e kg\n", mb.liquid, mb.gas,
                mb.gasRemoved);

    // Baseline: the same liquid, a fresh ambient-air gas solver holding a copy of the vapour.
    gas::GasSettings bs = gs;
    bs.method = gas::Method::Ambient;
    bs.turbulence = gas::Turbulence::None; // it simulates its air
    const Real half = Real(0.5 * o.domain);
    bs.domain = Aabb{Vec3(-half, Real(-4 * double(H)), -half), Vec3(half, Real(o.height), half)};
    gas::GasSolver ambientGas(bs);
    bench::copyGas(fastGas, ambientGas);
    gas::PhaseTransition baseline(ambientGas, side, ps);
    baseline.addHeater(plate, Real(o.heater));
    const double baseWall = timeBaseline(baseline, ambientGas, liquid, o, dt);
    const double fastRate = o.steps / fastWall, baseRate = o.baselineSteps / baseWall;
    std::printf("ratio fast / baseline: %.2fx coupled, %.2fx gas only\n", fastRate / baseRate,
                (double(fast.timings().steps) / fast.timings().gas)
                    / (double(baseline.timings().steps) / baseline.timings().gas));
    return 0;
}

/// The pan, its water and the heater.
void addPanOptions(CLI::App& app, Options& o)
{
    app.add_option("--spacing", o.spacing, "liquid spacing h (m)");
    app.add_option("--half-width", o.halfWidth, "pan inside half width a (m)");
    app.add_option("--depth", o.depth, "water depth (m)");
    app.add_option("--heater", o.heater, "plate temperature (K)");
}

/// The warm-up and the measured steps of both methods.
void addStepOptions(CLI::App& app, Options& o)
{
    app.add_option("--vapour", o.vapourTarget, "vapour particles before the measurement");
    app.add_option("--max-warmup", o.maxWarmup, "most warm-up steps");
    app.add_option("--steps", o.steps, "measured fast steps");
    app.add_option("--baseline-steps", o.baselineSteps, "measured baseline steps");
}

/// The command line into `o`: the pan, the steps, then the baseline's air box.
void addOptions(CLI::App& app, Options& o)
{
    addPanOptions(app, o);
    addStepOptions(app, o);
    app.add_option("--turbulence", o.turbulence, "the fast gas's turbulence model (auto, none, "
                                                 "entrainment)");
    app.add_option("--domain", o.domain, "baseline air box width and depth (m)");
    app.add_option("--height", o.height, "baseline air box height above the pan bottom (m)");
}

} // namespace

int main(int argc, char** argv)
{
    return bench::benchMain(
        argc, argv, "bench_gas",
        "bench_gas: [RYY15] Fig. 4 boiling scene, fast gas vs ambient-air baseline", addOptions,
        run);
}
