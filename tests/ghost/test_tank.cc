/// @file   test_tank.cc
/// @brief  Hydrostatic tank ([SB12] Sec. 4.4): a column of liquid at rest in a box with
///         ghost-solid walls; pressure grows as rho0 g depth and no particle is inside a wall.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include "common/Shapes.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.01);

/// Open-top box container: walls 4 h thick around the inside [-a, a] x [0, top] x [-a, a].
openvdb::FloatGrid::Ptr tankGrid(Real a, Real top)
{
    return ghostfx::testing::openTankGrid(a, top, 4 * double(H), H / 2);
}

/// Least-squares slope of pressure against height over the liquid away from the walls and
/// the surface (their pressure carries the boundary's sampling noise).
struct HydrostaticFit
{
    double slope = 0, meanDensity = 0, particles = 0, top = 0;
};

HydrostaticFit fitPressureSlope(const ParticleSet& p, Real a)
{
    HydrostaticFit fit;
    double top = -1e9;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid) top = std::max(top, double(p.positions()[i][1]));
    }
    double sy = 0, sp = 0, syy = 0, syp = 0, n = 0, rhoSum = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        const Vec3& x = p.positions()[i];
        if (std::abs(x[0]) > a - 2 * H || std::abs(x[2]) > a - 2 * H) continue;
        if (x[1] < 2 * H || x[1] > top - 2 * H) continue;
        const double y = x[1], pressure = p.pressures()[i];
        sy += y;
        sp += pressure;
        syy += y * y;
        syp += y * pressure;
        n += 1;
        rhoSum += p.densities()[i];
    }
    fit.slope = (n * syp - sy * sp) / (n * syy - sy * sy);
    fit.meanDensity = rhoSum / n;
    fit.particles = n;
    fit.top = top;
    return fit;
}

void expectHydrostaticTank(AirWeights weights)
{
    const Real a = Real(0.05), depth = Real(0.12);
    GhostSettings s;
    s.airWeights = weights;
    s.spacing = H;
    s.seed = 9;
    GhostSolver solver(s);
    const LevelSet tank = makeLevelSet(tankGrid(a, Real(0.2)), "tank");
    solver.addSolid(tank);
    solver.addLiquid(
        makeLevelSet(makeBoxLevelSet(Vec3(-a, 0, -a), Vec3(a, depth, a), H / 2), "water"));
    // [SB12] defaults: k = 2000 Pa (sound speed 3.7 m/s), 20 substeps at 30 fps would be
    // dt = 1/600 s; half that keeps the acoustic CFL number at 0.31.
    const Real dt = Real(1) / Real(1200);
    // The column settles for 0.3 s, then is measured over 0.3 s. With the paper's soft k it
    // still rings in its lowest acoustic mode (period about 0.18 s here): the instantaneous
    // slope swings by +-20 % around rho g, so one snapshot measures the phase of the ringing,
    // not hydrostatics. The mean over the window (60 snapshots, 1.7 periods) is what must
    // match; its residual is the mean acceleration of the column over the window.
    const int settleSteps = 360, measureSteps = 360, every = 6;
    const ParticleSet& p = solver.particles();
    double slopeSum = 0, rhoSum = 0, fitted = 0, top = -1e9, worstInside = 0;
    int snapshots = 0;
    for (int k = 0; k < settleSteps + measureSteps; ++k) {
        solver.step(dt);
        if (k < settleSteps || (k - settleSteps) % every != 0) continue;
        const HydrostaticFit fit = fitPressureSlope(p, a);
        slopeSum += fit.slope;
        rhoSum += fit.meanDensity;
        fitted += fit.particles;
        top = fit.top;
        ++snapshots;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] == ParticleKind::Liquid) {
                worstInside = std::min(worstInside, double(tank.phi(p.positions()[i])));
            }
        }
    }
    double maxSpeed = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid)
            maxSpeed = std::max(maxSpeed, double(p.velocities()[i].length()));
    }
    const double slope = slopeSum / snapshots;
    // Hydrostatics: dp/dy = -rho g. With the paper's soft k = 2000 Pa the column compresses
    // (rho up to 1.08 rho0 at 12 cm depth), so compare with the mean density of the fitted
    // particles, and report rho0 g beside it.
    const double rhoMean = rhoSum / snapshots;
    const double expected = -rhoMean * 9.81;
    std::printf("[measured] tank (%s air weights): mean dp/dy %.1f Pa/m over %d snapshots vs -rho "
                "g %.1f (%.2f %%; "
                "-rho0 g %.1f), mean rho %.1f, %.0f particles per fit, deepest liquid inside wall "
                "%.2e m, max speed %.3f m/s, top %.4f m\n",
                weights == AirWeights::Matched ? "matched" : "complete", slope, snapshots, expected,
                100 * (slope - expected) / expected, -double(s.restDensity) * 9.81, rhoMean,
                fitted / snapshots, worstInside, maxSpeed, top);
    // SPH pressure noise over 0.1 m of height: bound 5 %.
    EXPECT_NEAR(slope / expected, 1.0, 0.05);
    // Collision projection keeps every particle out (at every snapshot): tolerance 1e-3 voxel of projection.
    EXPECT_GE(worstInside, -0.01 * double(H));
    // At rest: residual speeds well below sqrt(g h) = 0.31 m/s. The fastest of 1,400 particles
    // is an extreme of the sampling's noise: over 24 sample realisations (the sampler's seed
    // salted, 6 each for both weights and both volume relaxations; bench/history/diary-2026-11.md,
    // "Tests that hold over sample realisations") it measured 0.057-0.112 m/s. Bound: half of
    // sqrt(g h), 0.15 m/s.
    EXPECT_LT(maxSpeed, 0.15);
}

} // namespace

// With the default air weights ("complete"). Measured: slope +2.8 %, 0.072 m/s (float); +2.8 %,
// 0.053 m/s (double).
TEST(HydrostaticTank, PressureGrowsAsRhoGDepthAndNoParticleEntersTheWalls)
{
    expectHydrostaticTank(GhostSettings().airWeights);
}

// Matched air weights (GhostSettings::airWeights) must keep the tank too.
// Measured: slope -0.08 %, 0.061 m/s (float); +0.84 %, 0.083 m/s (double).
TEST(HydrostaticTank, MatchedAirWeightsHoldTheTankToo)
{
    expectHydrostaticTank(AirWeights::Matched);
}

namespace {

/// The fastest liquid particle (m/s) over a 0.15 s run of a 10 cm block dropped 3 h onto the
/// floor of the open tank, with DFSPH; the solves' statistics in `stats`.
double landingBlockMaxSpeed(const GhostSettings& s, PressureSolveStats& stats)
{
    const Real a = Real(0.08);
    const LevelSet tank = makeLevelSet(tankGrid(a, Real(0.3)), "tank");
    GhostSolver solver(s);
    solver.addSolid(tank);
    solver.addLiquid(makeLevelSet(
        makeBoxLevelSet(Vec3(-0.05f, 3 * H, -0.05f), Vec3(0.05f, 3 * H + 0.1f, 0.05f), H / 2),
        "block"));
    double maxSpeed = 0;
    for (double t = 0; t < 0.15;) {
        const Real dt = solver.stableTimeStep();
        solver.step(dt);
        t += double(dt);
        const ParticleSet& p = solver.particles();
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            maxSpeed = std::max(maxSpeed, double(p.velocities()[i].length()));
        }
    }
    stats = solver.pressureSolveStats();
    return maxSpeed;
}

GhostSettings landingSettings()
{
    GhostSettings s;
    s.spacing = H;
    s.pressure = PressureModel::Dfsph;
    s.seed = 3;
    return s;
}

/// The landing block of ALandingBlockLeavesNoParticleSqueezed with `option` applied to its
/// settings, at 3 h and 2.5 h support: no solve stops short and the fastest liquid stays
/// below `bound` (m/s).
void expectCalmLanding(const char* name, double bound,
                       const std::function<void(GhostSettings&)>& option)
{
    for (const Real support : {Real(3), Real(2.5)}) {
        GhostSettings s = landingSettings();
        s.supportFactor = support;
        option(s);
        PressureSolveStats stats;
        const double maxSpeed = landingBlockMaxSpeed(s, stats);
        std::printf("[measured] landing block, %s, support %.1f h: max liquid speed %.3f m/s, "
                    "%llu unconverged solves\n",
                    name, double(support), maxSpeed, (unsigned long long)stats.unconverged);
        EXPECT_LT(maxSpeed, bound) << name << ", support " << support;
        EXPECT_EQ(stats.unconverged, 0u) << name << ", support " << support;
    }
}

} // namespace

// A liquid block dropped 3 h onto the floor of a tank, with DFSPH: the small cousin of
// SPlisHSPlasH's dam break at 100k, whose cube blew up after its 1 m/s landing until the solves
// also bounded each particle's error (DfsphSettings::PEAK_FACTOR; bench/history/diary-2026-11.md,
// "DFSPH: a peak limit"; Dfsph.OneParticleDrivenIntoItsNeighbourIsStoppedThoughTheMeanIsMet tests
// the limit itself: at this size the mean alone already keeps every particle within it). Measured
// over the fall and the landing: the largest error of one particle any solve left (bound: the
// peak limit, 3 %), the solves that stopped short (none), and the fastest liquid (the landing at
// 0.77 m/s throws a few particles at about 3.3 m/s at this coarse size; bound 5 m/s: a splash,
// not a blow-up).
TEST(HydrostaticTank, ALandingBlockLeavesNoParticleSqueezed)
{
    const GhostSettings s = landingSettings();
    PressureSolveStats stats;
    const double maxSpeed = landingBlockMaxSpeed(s, stats);
    std::printf("[measured] landing block: largest error of one particle %.2e (density) / %.2e "
                "(divergence), %llu unconverged solves, max liquid speed %.3f m/s, %.2f density + "
                "%.2f divergence iterations per step\n",
                stats.largestDensityError, stats.largestDivergenceError,
                (unsigned long long)stats.unconverged, maxSpeed,
                double(stats.densityIterations) / double(stats.steps),
                double(stats.divergenceIterations) / double(stats.steps));
    EXPECT_LE(stats.largestDensityError, DfsphSettings::PEAK_FACTOR * double(s.dfsph.densityError));
    EXPECT_LE(stats.largestDivergenceError,
              DfsphSettings::PEAK_FACTOR * double(s.dfsph.divergenceError));
    EXPECT_EQ(stats.unconverged, 0u);
    EXPECT_LT(maxSpeed, 5.0);
}

// settings.dfsph.air_density "fill": the air counts only up to the density the liquid lacks, so
// air crowded under the landing and up the walls cannot squeeze a sheet's particles. With
// "full" the fastest particle of this landing (0.77 m/s) reached 2.0-3.5 m/s at 3 h support and
// 3.6-8.6 m/s at 2.5 h over six sample realisations (settings.seed 1-6; the thrown particles
// sat at 1.3-1.5 rho0 among 30-66 air particles and 7-22 liquid ones); with "fill" 1.6-2.2 and
// 2.2-2.7 m/s (bench/history/diary-2026-11.md, "DFSPH: ghost air that fills and never compresses").
// Bound 3.5 m/s at both supports: the realisations' largest with 30 % to spare, below what "full"
// reaches at 2.5 h for five of the six.
TEST(HydrostaticTank, AirThatFillsKeepsTheLandingsSplashDownAtEitherSupport)
{
    expectCalmLanding("air_density fill", 3.5, [](GhostSettings& s) {
        s.dfsph.airDensity = DfsphSettings::AirDensity::Fill;
    });
}

// settings.dfsph.air_resampling "time": the air layer resampled and faded as far per second as
// [SB12]'s steps take it (a DFSPH step spans 2 to 5 of them here), so it has no time to crowd
// under the landing and up the walls between resamplings. With one phase a step ("step", the
// default) the fastest particle of this landing (0.77 m/s) reached 2.0-3.5 m/s at 3 h support
// and 3.6-8.6 m/s at 2.5 h over six sample realisations (settings.seed 1-6); with "time"
// 1.47-2.01 and 2.21-2.57 m/s (bench/history/diary-2026-11.md, "DFSPH: the air resampled as often
// as [SB12]'s steps"). Bound 3 m/s at both supports: the realisations' largest with 15 % to
// spare, below what "step" reaches at 2.5 h in all six.
TEST(HydrostaticTank, AirResampledAsOftenAsSb12sStepsKeepsTheLandingsSplashDown)
{
    expectCalmLanding("air_resampling time", 3.0, [](GhostSettings& s) {
        s.dfsph.airResampling = DfsphSettings::AirResampling::Time;
    });
}
