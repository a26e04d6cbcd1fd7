/// @file   test_dfsph.cc
/// @brief  Ghost SPH with the implicit DFSPH pressure (settings.pressure = dfsph): a still tank
///         held at the set density error with hydrostatic pressure, free fall, mass and thread
///         determinism, resume bit for bit (and refusal of a Tait state), error limits and
///         time-step caps at their extremes.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>

#include "common/LiquidMeasures.h"
#include "common/ResumeScene.h"
#include "common/SameParticles.h"
#include "common/Shapes.h"
#include "common/StateDiff.h"
#include "common/Tap.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;
using ghostfx::testing::liquidCentre;
using ghostfx::testing::liquidMass;

namespace {

constexpr Real H = Real(0.01);

GhostSettings dfsphSettings()
{
    GhostSettings s;
    s.spacing = H;
    s.seed = 9;
    s.pressure = PressureModel::Dfsph;
    s.substeps = 0; // CFL steps on the flow speed
    return s;
}

/// A water block collapsing in a closed box: the violent case of the extremes below.
struct Collapse
{
    LevelSet tank =
        makeLevelSet(ghostfx::testing::closedTankGrid(
                         Vec3(0), Vec3(Real(0.3), Real(0.2), Real(0.1)), 4 * double(H), H / 2),
                     "tank");
    LevelSet water = makeLevelSet(
        makeBoxLevelSet(Vec3(0), Vec3(Real(0.1), Real(0.15), Real(0.1)), H / 2), "water");
};

/// What StillTankHoldsTheDensityLimitAndHydrostaticPressure measures (see its comment).
struct StillTank
{
    double solveError = 0, limit = 0;
    std::uint64_t unconverged = 0;
    double interiorError = 0, topError = 0; ///< mean |rho / rho0 - 1|
    double slope = 0;                       ///< dp/dd / (rho0 g)
    double worstLayer = 0;                  ///< of rho0 g D
    double worstInside = 0;                 ///< deepest phi of the tank (m)
    double interiorSpeed = 0, topSpeed = 0; ///< m/s
    double densityIterations = 0, divergenceIterations = 0; ///< per step
};

/// The still tank of the tests below with kernel support `supportFactor` h (and the divergence
/// solve's warm start on or off). With `lift` the tank accelerates upwards at lift m/s^2 from
/// rest at t = 0 (a moving solid): positions, speeds and depths are then taken in its frame,
/// where the liquid feels gravity g + lift, and the slope is against rho0 (g + lift).
StillTank measureStillTank(Real supportFactor, bool divergenceWarmStart = true, double lift = 0)
{
    const Real a = Real(0.05), depth = Real(0.12);
    GhostSettings s = dfsphSettings();
    s.supportFactor = supportFactor;
    s.dfsph.divergenceWarmStart = divergenceWarmStart;
    GhostSolver solver(s);
    const LevelSet tank =
        makeLevelSet(ghostfx::testing::openTankGrid(a, Real(0.2), 4 * double(H), H / 2), "tank");
    if (lift == 0) solver.addSolid(tank);
    else {
        solver.addMovingSolid(tank, [lift](double t) {
            RigidTransform xf;
            xf.translation = Vec3(0, Real(0.5 * lift * t * t), 0);
            xf.translationRate = Vec3(0, Real(lift * t), 0);
            xf.hasRates = true;
            return xf;
        });
    }
    // The tank's frame: its rise and speed at the solver's time.
    auto rise = [&] { return 0.5 * lift * solver.time() * solver.time(); };
    auto frameSpeed = [&] { return Vec3(0, Real(lift * solver.time()), 0); };
    solver.addLiquid(
        makeLevelSet(makeBoxLevelSet(Vec3(-a, 0, -a), Vec3(a, depth, a), H / 2), "water"));
    const ParticleSet& p = solver.particles();
    while (solver.time() < 0.5) solver.step(solver.stableTimeStep());
    solver.resetTimings();

    const double rho0 = s.restDensity, g = 9.81 + lift, R = s.supportRadius();
    std::map<int, double> layerP, layerN;
    double interiorErr = 0, interiorN = 0, topErr = 0, topN = 0, solveErr = 0, worstInside = 0,
           interiorSpeed = 0, topSpeed = 0, surfaceSum = 0;
    double sd = 0, sp = 0, sdd = 0, sdp = 0, fitted = 0;
    int snapshots = 0;
    while (solver.time() < 1.0) {
        solver.step(solver.stableTimeStep());
        solveErr = std::max(solveErr, solver.pressureSolveStats().lastDensityError);
        ++snapshots;
        const double floor = rise();
        const Vec3 u = frameSpeed();
        double top = -1e9;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] == ParticleKind::Liquid)
                top = std::max(top, double(p.positions()[i][1]) - floor);
        }
        double topMean = 0, topCount = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            const double y = double(p.positions()[i][1]) - floor;
            if (y > top - 0.5 * H) {
                topMean += y;
                topCount += 1;
            }
        }
        const double surface = topMean / topCount + 0.5 * H;
        surfaceSum += surface;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            const Vec3 x = p.positions()[i] - Vec3(0, Real(floor), 0);
            worstInside = std::min(worstInside, double(tank.phi(x)));
            const double e = std::abs(p.densities()[i] / rho0 - 1);
            const double speed = (p.velocities()[i] - u).length();
            if (x[1] > surface - 1.5 * H) {
                topErr += e;
                topN += 1;
                topSpeed = std::max(topSpeed, speed);
            } else {
                interiorErr += e;
                interiorN += 1;
                interiorSpeed = std::max(interiorSpeed, speed);
            }
            if (std::abs(x[0]) > a - 2 * H || std::abs(x[2]) > a - 2 * H) continue;
            const double d = surface - x[1];
            if (d < 1.5 * H || x[1] < R) continue;
            const int layer = int(std::floor(d / H));
            layerP[layer] += p.pressures()[i] - rho0 * g * d;
            layerN[layer] += 1;
            sd += d;
            sp += p.pressures()[i];
            sdd += d * d;
            sdp += d * p.pressures()[i];
            fitted += 1;
        }
    }
    const double limit = s.dfsph.densityError;
    const double scale = rho0 * g * surfaceSum / snapshots;
    const double slope = (fitted * sdp - sd * sp) / (fitted * sdd - sd * sd);
    double worstLayer = 0;
    for (const auto& [layer, sum] : layerP) {
        const double mean = sum / layerN[layer];
        worstLayer = std::max(worstLayer, std::abs(mean) / scale);
        std::printf("[measured] dfsph tank, support %.1f h, layer %d cm: p - rho0 g d = %+.1f Pa "
                    "(%+.2f %% of "
                    "rho0 g D)\n",
                    double(supportFactor), layer, mean, 100 * mean / scale);
    }
    const PressureSolveStats& st = solver.pressureSolveStats();
    std::printf("[measured] dfsph tank, support %.1f h: %d steps, solve error up to %.2e (limit "
                "%.0e), density "
                "error interior %.2e top layer %.2e, dp/dd %.1f Pa/m (rho0 g %.1f, %+.2f %%), "
                "worst layer %.2f %% of rho0 g D (%.0f Pa), deepest inside wall %.1e m, max "
                "speed interior %.3f top %.3f m/s, iterations %.1f + %.1f per step, unconverged "
                "%llu\n",
                double(supportFactor), snapshots, solveErr, limit, interiorErr / interiorN,
                topErr / topN, slope, rho0 * g, 100 * (slope / (rho0 * g) - 1), 100 * worstLayer,
                scale, worstInside, interiorSpeed, topSpeed,
                double(st.densityIterations) / st.steps, double(st.divergenceIterations) / st.steps,
                static_cast<unsigned long long>(st.unconverged));
    StillTank m;
    m.solveError = solveErr;
    m.limit = limit;
    m.unconverged = st.unconverged;
    m.interiorError = interiorErr / interiorN;
    m.topError = topErr / topN;
    m.slope = slope / (rho0 * g);
    m.worstLayer = worstLayer;
    m.worstInside = worstInside;
    m.interiorSpeed = interiorSpeed;
    m.topSpeed = topSpeed;
    m.densityIterations = double(st.densityIterations) / double(st.steps);
    m.divergenceIterations = double(st.divergenceIterations) / double(st.steps);
    return m;
}

/// The bounds of StillTankHoldsTheDensityLimitAndHydrostaticPressure (see its comment), with
/// the pressure slope's relative tolerance `slopeTolerance`, the fastest interior particle's
/// bound `interiorSpeed` (m/s) and the worst layer's `worstLayer` (of rho0 g D).
void expectStillTankHolds(const StillTank& m, double slopeTolerance, double interiorSpeed = 0.3,
                          double worstLayer = 0.06)
{
    EXPECT_LE(m.solveError, m.limit);
    EXPECT_EQ(m.unconverged, 0u);
    EXPECT_LT(m.interiorError, 0.005);
    EXPECT_LT(m.topError, 0.02);
    EXPECT_NEAR(m.slope, 1.0, slopeTolerance);
    EXPECT_LT(m.worstLayer, worstLayer);
    EXPECT_GE(m.worstInside, -0.01 * double(H));
    EXPECT_LT(m.interiorSpeed, interiorSpeed);
    EXPECT_LT(m.topSpeed, 0.25);
}

/// The zero-gravity cube of ZeroGravityCubeKeepsItsShape with kernel support `supportFactor`
/// h: the radius of gyration's relative change over 2 s and the fastest liquid over 1-2 s.
std::pair<double, double> zeroGravityCube(Real supportFactor)
{
    GhostSettings s = dfsphSettings();
    s.spacing = Real(0.025);
    s.gravity = Vec3(0);
    s.seed = 1;
    s.supportFactor = supportFactor;
    s.initialRelaxation = 0;
    GhostSolver solver(s);
    solver.addLiquid(makeLevelSet(makeBoxLevelSet(Vec3(0), Vec3(Real(0.2)), Real(0.0125)), "cube"));
    auto gyration = [&]() {
        const ParticleSet& p = solver.particles();
        Vec3d com = liquidCentre(p);
        double sum = 0, n = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            sum += (Vec3d(p.positions()[i]) - com).lengthSqr();
            n += 1;
        }
        return std::sqrt(sum / n);
    };
    solver.step(solver.stableTimeStep());
    const double start = gyration();
    double lateSpeed = 0;
    while (solver.time() < 2.0) {
        solver.step(solver.stableTimeStep());
        if (solver.time() < 1.0) continue;
        for (std::size_t i = 0; i < solver.particles().size(); ++i) {
            if (solver.particles().kinds()[i] == ParticleKind::Liquid)
                lateSpeed =
                    std::max(lateSpeed, double(solver.particles().velocities()[i].length()));
        }
    }
    const double change = gyration() / start - 1;
    std::printf("[measured] dfsph zero-g cube, support %.1f h, 2 s: %llu steps, gyration %+.2f %%, "
                "max speed over "
                "1-2 s %.3f m/s\n",
                double(supportFactor), static_cast<unsigned long long>(solver.stepCount()),
                100 * change, lateSpeed);
    return {change, lateSpeed};
}

} // namespace

TEST(Dfsph, StillTankHoldsTheDensityLimitAndHydrostaticPressure)
{
    // The open tank of HydrostaticTank (test_tank.cc), 12 cm of water at 1 cm spacing, CFL
    // steps capped at the default 5 ms, after 0.5 s of settling, over 0.5 s (about 100 steps):
    //  - every solve meets its limit and none stops at the cap;
    //  - density: the Tait step compresses this column by up to 6.8 % at the bottom (rho0 g D
    //    = 1.18 kPa against k = 2 kPa; measured mean error 3.3 %); DFSPH holds the interior
    //    within 0.5 % (the relaxed density target, DfsphSettings::densityRelaxation, leaves
    //    the sampled packing's error to decay) and the top layer, where a tenth of the air is
    //    resampled every step, within 2 %;
    //  - pressure: the least-squares slope of p against depth d below the free surface (half a
    //    spacing above the top layer's mean height), between the top layer and R above the
    //    floor, is rho0 g within 1 % (the bound), and each 1 cm layer's mean p within
    //    3 % of rho0 g D of rho0 g d. The pressure is the solver's Shepard average of the
    //    pressure terms (DfsphPressure.cc: single particles' terms scatter by tens of percent in
    //    patterns the SPH gradient cannot see). Within R of the floor the Shepard average
    //    reaches no liquid below and p is not rho0 g d; left out;
    //  - no liquid inside the walls; residual speeds below 0.15 m/s interior and 0.25 m/s in
    //    the top layer (sqrt(g h) = 0.31 m/s is the speed a particle-sized disturbance
    //    reaches).
    // Measured with mirrored walls (DfsphSettings::WallPressure::Mirror) over six sample
    // realisations (seeds 9 and 1-5; bench/history/diary-2026-11.md, "DFSPH: ghost solids as mirror
    // images"): slope -0.07 to +0.35 %, worst layer 1.81-2.13 %, interior density error
    // 0.32-0.36 %, top layer 0.89-1.07 %, fastest interior particle 0.048-0.060 m/s. With
    // the walls' own pressure term (WallPressure::Own) the slope is +0.6 to +1.4 %, the worst
    // layer 2.2-3.8 % and the interior speed up to 0.26 m/s.
    expectStillTankHolds(measureStillTank(GhostSettings().supportFactor), 0.01, 0.15, 0.03);
}

TEST(Dfsph, TankAcceleratingUpwardsHoldsItsHydrostaticPressure)
{
    // The still tank, moving: it accelerates upwards at g / 2 from rest, so in its frame the
    // liquid feels 1.5 g and its pressure is rho0 1.5 g d. A moving wall's mirrored ghost
    // extrapolates the liquid's pressure with g - a_s, a_s the wall's own acceleration
    // (Adami et al. 2012); and its velocity enters the rate of density change as
    // c sum_s M (v_i - v_s) . grad W_is. Measured over six sample realisations (seeds 9 and
    // 1-5): slope -0.87 to +0.54 %, worst layer 1.96-3.16 % of rho0 1.5 g D, interior density
    // error 0.49-0.56 %, fastest particle in the tank's frame 0.13-0.18 m/s inside and 0.15-0.26
    // at the top. Extrapolated with g alone the slope would be +1.97 to +4.39 % and the worst
    // layer 3.6-5.3 %; with v_s of the wrong sign the rising floor squeezes the liquid to 3-5
    // rho0 while the solves report convergence, which this test catches.
    // Bounds: slope 1.5 % (the still tank's 1 % plus the measured spread; every seed of the
    // g-only extrapolation is outside it), worst layer 4 %, interior density error 1 % (a solve
    // stopping at its limit leaves up to density_error / density_relaxation = 1 %), top layer
    // 2 %, speeds 0.3 / 0.4 m/s (the still tank's bounds times about sqrt(1.5), plus spread).
    const StillTank m = measureStillTank(GhostSettings().supportFactor, true, 9.81 / 2);
    EXPECT_LE(m.solveError, m.limit);
    EXPECT_EQ(m.unconverged, 0u);
    EXPECT_NEAR(m.slope, 1.0, 0.015);
    EXPECT_LT(m.worstLayer, 0.04);
    EXPECT_LT(m.interiorError, 0.01);
    EXPECT_LT(m.topError, 0.02);
    EXPECT_GE(m.worstInside, -0.01 * double(H));
    EXPECT_LT(m.interiorSpeed, 0.3);
    EXPECT_LT(m.topSpeed, 0.4);
}

TEST(Dfsph, StillTankAtTwoSpacingsSupportHoldsTheDensityLimit)
{
    // The same tank with kernel_support 2 (SPlisHSPlasH's support, 4 particle radii): a full
    // neighbourhood is (2/3)^3 of [SB12]'s, so the spray threshold (DfsphPressure.cc,
    // MIN_NEIGHBOURS) scales with it; fixed at the 3 h count, the top layer went unsolved
    // (its mean density error 6.8 %, the limit below 2 %). Measured over six sample
    // realisations (seeds 9 and 1-5) with mirrored walls: interior 0.36-0.45 %, top layer
    // 0.84-1.03 %, pressure slope -0.55 to +1.48 % (+2.1 to +3.1 % with the walls' own
    // pressure term), worst layer 1.75-2.53 %, interior speed 0.07-0.11 m/s. Bounds: the 3 h
    // test's, with the slope's 2 % and the worst layer's 4 %.
    expectStillTankHolds(measureStillTank(Real(2)), 0.02, 0.3, 0.04);
}

TEST(Dfsph, DivergenceSolveFromZeroIsCheaperAndHoldsTheTank)
{
    // settings.dfsph.divergence_warm_start false: the divergence solve starts each step from
    // zero. What advection leaves is mostly within its limit, so it almost never iterates, and
    // it saves the warm start's gradient pass. The solve passes a step (4 with both warm
    // starts, 3 without, plus 2 an iteration) fall by about a quarter: measured 5.08 -> 3.62
    // in float with mirrored walls (6.76 -> 5.12 with the walls' own pressure term; bound: at
    // least 15 % fewer). With the own term the tank was noisier from zero (seed 9: interior
    // density error 0.46 against 0.32 %, worst layer 5.1 against 3.5 %, fastest interior
    // particle 0.19 against 0.15 m/s, 0.32 against 0.17 in double); mirrored, the two hardly
    // differ (seed 9, float: 0.33 against 0.36 %, 2.11 against 1.81 %, slope +0.34 against
    // +0.14 %, 0.061 against 0.053 m/s). Bounds: the default's, with the worst layer's 4 % and
    // the interior speed's 0.3 m/s.
    const StillTank warm = measureStillTank(GhostSettings().supportFactor, true);
    const StillTank cold = measureStillTank(GhostSettings().supportFactor, false);
    auto passes = [](const StillTank& m, int start) {
        return start + 2 * (m.densityIterations + m.divergenceIterations);
    };
    std::printf("[measured] dfsph tank, divergence solve from zero: %.2f solve passes a step "
                "against %.2f warm\n",
                passes(cold, 3), passes(warm, 4));
    expectStillTankHolds(cold, 0.01, 0.3, 0.04);
    EXPECT_LT(cold.divergenceIterations, 0.1);
    EXPECT_LT(passes(cold, 3), 0.85 * passes(warm, 4));
}

TEST(Dfsph, FreeFallFollowsGravity)
{
    // No solids: the centre of mass falls as the integrator's g dt^2 N (N + 1) / 2 with N
    // equal steps. The air moves with the liquid (it falls too), so the solve has nothing to
    // correct but the sampling's density scatter. Bound as for the Tait step: 2 % and 1 cm.
    GhostSettings s = dfsphSettings();
    s.substeps = 0;
    GhostSolver solver(s);
    solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.04), H / 2), "ball"));
    const Vec3d start = liquidCentre(solver.particles());
    const int steps = 100;
    const double dt = 0.2 / steps;
    for (int k = 0; k < steps; ++k) solver.step(Real(dt));
    const double expected = 9.81 * dt * dt * steps * (steps + 1) / 2.0;
    const Vec3d drop = start - liquidCentre(solver.particles());
    std::printf("[measured] dfsph free fall: drop %.5f m, expected %.5f m (%.3f %%), sideways "
                "%.2e m\n",
                drop.y(), expected, 100.0 * (drop.y() - expected) / expected,
                std::hypot(drop.x(), drop.z()));
    EXPECT_NEAR(drop.y(), expected, 0.02 * expected);
    EXPECT_LT(std::hypot(drop.x(), drop.z()), 1e-2);
}

TEST(Dfsph, MassIsConservedAndOneAndTwoThreadsAgreeBitForBit)
{
    const Collapse scene;
    auto run = [&](int threads) {
        parallel::ThreadLimit limit(threads);
        GhostSolver solver(dfsphSettings());
        solver.addSolid(scene.tank);
        solver.addLiquid(scene.water);
        solver.step(solver.stableTimeStep());
        const std::size_t count = solver.count(ParticleKind::Liquid);
        const double mass = liquidMass(solver.particles());
        for (int k = 0; k < 40; ++k) solver.step(solver.stableTimeStep());
        EXPECT_EQ(solver.count(ParticleKind::Liquid), count);
        EXPECT_EQ(liquidMass(solver.particles()), mass);
        return solver.particles();
    };
    const ParticleSet one = run(1), two = run(2);
    ghostfx::testing::expectSameParticles(one, two, ghostfx::testing::AlsoCompare::Pressures);
}

// settings.dfsph.keep_gradients: the solves read each pair's m_j grad W_ij as the factor pass
// kept it, or evaluate the kernel again in every pass; the same solve either way. Driven with
// the same steps from the same start, the two must agree to float rounding (the products are
// taken in another order: m_j g(r) (x_i - x_j) (k_i + k_j) against m_j (k_i + k_j) g(r)
// (x_i - x_j)), take the same iterations, and the kept gradients must cost 12 bytes a pair.
TEST(Dfsph, KeptKernelGradientsGiveTheRecomputedSolve)
{
    const Collapse scene;
    GhostSettings kept = dfsphSettings(), recomputed = dfsphSettings();
    kept.dfsph.keepGradients = true;
    recomputed.dfsph.keepGradients = false;
    GhostSolver a(kept), b(recomputed);
    for (GhostSolver* s : {&a, &b}) {
        s->addSolid(scene.tank);
        s->addLiquid(scene.water);
    }
    const int steps = 10;
    for (int k = 0; k < steps; ++k) {
        const Real dt = a.stableTimeStep();
        a.step(dt);
        b.step(dt);
    }
    const ParticleSet& pa = a.particles();
    const ParticleSet& pb = b.particles();
    ASSERT_EQ(pa.size(), pb.size());
    std::map<std::uint64_t, std::size_t> where;
    for (std::size_t i = 0; i < pb.size(); ++i) where[pb.ids()[i]] = i;
    double fastest = 0, dv = 0, dx = 0;
    for (std::size_t i = 0; i < pa.size(); ++i) {
        if (pa.kinds()[i] != ParticleKind::Liquid) continue;
        const auto it = where.find(pa.ids()[i]);
        ASSERT_NE(it, where.end());
        fastest = std::max(fastest, double(pa.velocities()[i].length()));
        dv = std::max(dv, double((pa.velocities()[i] - pb.velocities()[it->second]).length()));
        dx = std::max(dx, double((pa.positions()[i] - pb.positions()[it->second]).length()));
    }
    const PressureSolveStats& sa = a.pressureSolveStats();
    const PressureSolveStats& sb = b.pressureSolveStats();
    const double extra = double(a.memoryUse().stepArrays) - double(b.memoryUse().stepArrays);
    const double perPair = extra / double(a.lastPairCount());
    std::printf("[measured] %d steps, kept against recomputed gradients: largest velocity "
                "difference %.2e m/s (fastest %.3f m/s), position %.2e m; iterations %llu + %llu "
                "against %llu + %llu; kept arrays %.1f bytes a liquid-solid-inclusive pair\n",
                steps, dv, fastest, dx, (unsigned long long)sa.densityIterations,
                (unsigned long long)sa.divergenceIterations,
                (unsigned long long)sb.densityIterations,
                (unsigned long long)sb.divergenceIterations, perPair);
    // Float rounding of ~100-term sums (relative 1e-7 each) carried through a few CG
    // iterations and ten steps: far below 1e-4 of the flow speed, and below a micrometre.
    const double eps = sizeof(Real) == 4 ? 1e-4 : 1e-10;
    EXPECT_LT(dv, eps * std::max(fastest, 0.1));
    EXPECT_LT(dx, eps * double(H));
    EXPECT_EQ(sa.densityIterations, sb.densityIterations);
    EXPECT_EQ(sa.divergenceIterations, sb.divergenceIterations);
    // 3 components of sizeof(Real) per liquid-fluid pair; pairCount also counts the solid
    // pairs (about a tenth here), which keep nothing, so a little under 3 sizeof(Real).
    EXPECT_GT(perPair, 2.0 * sizeof(Real));
    EXPECT_LE(perPair, 3.2 * sizeof(Real));
}

// settings.dfsph.kept_gradients_gb: a step whose kept gradients would take more than the limit
// recomputes them, the same code as keep_gradients false, so the run equals one with the
// gradients off bit for bit; it is counted, reports the bytes it would have needed, and holds
// none of the arrays. Under the limit nothing changes: bit for bit the default run.
TEST(Dfsph, KeptGradientsOverTheirMemoryLimitAreRecomputed)
{
    const Collapse scene;
    GhostSettings over = dfsphSettings(), off = dfsphSettings(), kept = dfsphSettings(),
                  under = dfsphSettings();
    off.dfsph.keepGradients = false;
    under.dfsph.keptGradientLimit = 1e9; // 1 GB: far above this scene's few MB
    GhostSolver a(kept), b(under), c(off);
    // The limit for the over-limit run: half what the first step keeps.
    for (GhostSolver* s : {&a, &b, &c}) {
        s->addSolid(scene.tank);
        s->addLiquid(scene.water);
    }
    const Real first = a.stableTimeStep();
    a.step(first);
    const double needed = a.pressureSolveStats().lastGradientBytes;
    ASSERT_GT(needed, 0.0);
    over.dfsph.keptGradientLimit = 0.5 * needed;
    GhostSolver d(over);
    d.addSolid(scene.tank);
    d.addLiquid(scene.water);
    b.step(first);
    c.step(first);
    d.step(first);
    const int steps = 5;
    for (int k = 0; k < steps; ++k) {
        const Real dt = a.stableTimeStep();
        for (GhostSolver* s : {&a, &b, &c, &d}) s->step(dt);
    }
    const PressureSolveStats& sd = d.pressureSolveStats();
    std::printf("[measured] kept gradients over their limit: %llu of %llu steps recomputed, "
                "%.0f bytes needed against a limit of %.0f; step arrays %.2f MB against %.2f "
                "MB kept\n",
                (unsigned long long)sd.recomputedSteps, (unsigned long long)sd.steps,
                sd.lastGradientBytes, over.dfsph.keptGradientLimit,
                double(d.memoryUse().stepArrays) / 1e6, double(a.memoryUse().stepArrays) / 1e6);
    EXPECT_EQ(sd.recomputedSteps, sd.steps);
    EXPECT_EQ(a.pressureSolveStats().recomputedSteps, 0u);
    EXPECT_EQ(b.pressureSolveStats().recomputedSteps, 0u);
    EXPECT_EQ(c.pressureSolveStats().recomputedSteps, 0u);
    EXPECT_EQ(c.pressureSolveStats().lastGradientBytes, 0.0);
    EXPECT_GT(sd.lastGradientBytes, over.dfsph.keptGradientLimit);
    // The kept arrays are 3 sizeof(Real) a liquid pair, most of the step arrays here
    // (measured in float: 0.11 MB against 1.02 MB); over the limit none are held.
    EXPECT_LT(double(d.memoryUse().stepArrays), 0.5 * double(a.memoryUse().stepArrays));
    EXPECT_LT(double(d.memoryUse().stepArrays), 1.1 * double(c.memoryUse().stepArrays));
    auto same = [](const GhostSolver& x, const GhostSolver& y) {
        return x.particles().ids() == y.particles().ids()
               && x.particles().positions() == y.particles().positions()
               && x.particles().velocities() == y.particles().velocities();
    };
    EXPECT_TRUE(same(d, c)) << "over the limit: not the recomputing solve";
    EXPECT_TRUE(same(b, a)) << "under the limit: not the kept solve";
}

// A frame's inner steps skip the reported pressure's pass (only output reads it): within a
// frame the liquid's pressures stay as the last frame left them, the frame's last step sets
// them, and they are then the ones a driver reporting every step gets, bit for bit, with the
// same motion.
TEST(Dfsph, AFrameReportsThePressureOnItsLastStepOnly)
{
    const Collapse scene;
    GhostSettings settings = dfsphSettings();
    settings.frameRate = 60;
    GhostSolver framed(settings), stepped(settings);
    for (GhostSolver* s : {&framed, &stepped}) {
        s->addSolid(scene.tank);
        s->addLiquid(scene.water);
        s->advanceFrame(); // the same first frame: the block starts to collapse
    }
    // The liquid's pressures as a sorted list (each step sorts the particles).
    auto liquidPressures = [](const GhostSolver& s) {
        std::vector<Real> p;
        const ParticleSet& set = s.particles();
        for (std::size_t i = 0; i < set.size(); ++i) {
            if (set.kinds()[i] == ParticleKind::Liquid) p.push_back(set.pressures()[i]);
        }
        std::sort(p.begin(), p.end());
        return p;
    };
    std::vector<Real> steps;
    std::vector<bool> changed;
    std::vector<Real> last = liquidPressures(framed);
    framed.setStepObserver([&](const GhostSolver& s, Real dt) {
        steps.push_back(dt);
        std::vector<Real> now = liquidPressures(s);
        changed.push_back(now != last);
        last = std::move(now);
    });
    framed.advanceFrame();
    for (Real dt : steps) stepped.step(dt);

    std::printf("[measured] frame of %zu steps: pressure set on steps", steps.size());
    for (std::size_t k = 0; k < changed.size(); ++k) {
        if (changed[k]) std::printf(" %zu", k + 1);
    }
    std::printf("\n");
    ASSERT_GE(steps.size(), 3u);
    EXPECT_EQ(std::count(changed.begin(), changed.end(), true), 1);
    EXPECT_TRUE(changed.back());
    ghostfx::testing::expectSameParticles(framed.particles(), stepped.particles(),
                                          ghostfx::testing::AlsoCompare::Pressures);
}

namespace {

/// Expect restoring `state` into a fresh solver with `settings` to be refused with a ValueError
/// whose message names both values: `saved` (the state's) and `wanted` (the solver's).
void expectRestoreRefused(const SolverState& state, const GhostSettings& settings,
                          const std::string& saved, const std::string& wanted)
{
    GhostSolver solver(settings);
    try {
        solver.restoreState(state);
        ADD_FAILURE() << "a state with " << saved << " restored into a solver with " << wanted;
    } catch (const ValueError& e) {
        EXPECT_THAT(e.what(), ::testing::HasSubstr(saved));
        EXPECT_THAT(e.what(), ::testing::HasSubstr(wanted));
    }
}

} // namespace

TEST(Dfsph, ResumeIsBitIdenticalAndATaitStateIsRefused)
{
    ghostfx::testing::ResumeScene scene(Method::Ghost, 0, Vec3(Real(0.05), 0, 0), 5);
    scene.settings.pressure = PressureModel::Dfsph;
    const int frames = 3, split = 1;
    SolverState saved;
    // Both air schedules: "time" carries its next phase and a fraction of one in the state.
    for (const auto schedule :
         {DfsphSettings::AirResampling::Step, DfsphSettings::AirResampling::Time}) {
        scene.settings.dfsph.airResampling = schedule;
        GhostSolver whole(scene.settings);
        scene.start(whole, frames);

        GhostSolver first(scene.settings);
        scene.start(first, split);
        saved = first.saveState();
        GhostSolver resumed(scene.settings);
        resumed.restoreState(saved);
        scene.addInputs(resumed);
        while (resumed.frame() < frames) resumed.advanceFrame();
        const std::string difference =
            ghostfx::testing::firstDifference(whole.saveState(), resumed.saveState());
        std::printf("[measured] dfsph resume, air_resampling %s: %llu steps, first difference "
                    "'%s'\n",
                    schedule == DfsphSettings::AirResampling::Time ? "time" : "step",
                    static_cast<unsigned long long>(whole.stepCount()), difference.c_str());
        EXPECT_EQ(difference, "");
        EXPECT_GT(whole.emittedCount(), 0u);
    }
    scene.settings.dfsph.airResampling = DfsphSettings::AirResampling::Step;

    // A state saved with the other pressure model names the key and both values.
    GhostSettings tait = scene.settings;
    tait.pressure = PressureModel::Tait;
    expectRestoreRefused(saved, tait, "settings.pressure = 'dfsph'", "'tait'");
    // So is one saved with the other air weights, and one that does not say which.
    GhostSettings matched = scene.settings;
    matched.airWeights = AirWeights::Matched;
    expectRestoreRefused(saved, matched, "saved with complete air weights",
                         "this solver has matched");
    SolverState old = saved;
    old.integers.erase("air_weights_complete");
    GhostSolver fromOld(scene.settings);
    EXPECT_THROW(fromOld.restoreState(old), ValueError);
}

TEST(Dfsph, ErrorLimitsAndTimeStepCapsAtTheirExtremesStayBounded)
{
    // A 10 x 15 x 10 cm block collapsing in a closed 30 x 20 x 10 cm box for 0.3 s (the front
    // hits the far wall at about 0.25 s). For density error limits 1e-2 to 1e-5 and time-step
    // caps from 0.5 ms to 20 ms: the run is finite, no liquid leaves the box, the speed stays
    // below 3 x the free-fall speed sqrt(2 g H) = 1.7 m/s of the column (a splash may
    // reach about twice it), and the solve meets its limit in the mean over the steps or
    // reports how often it did not. A limit too tight for the iteration cap must show as
    // unconverged solves, not as a silent result.
    const Collapse scene;
    struct Case
    {
        double error, maxDt;
        int maxIterations;
    };
    for (const Case c : {Case{1e-2, 5e-3, 100}, Case{1e-3, 5e-3, 100}, Case{1e-4, 5e-3, 100},
                         Case{1e-5, 5e-3, 100}, Case{1e-3, 5e-4, 100}, Case{1e-3, 2e-2, 100},
                         Case{1e-5, 5e-3, 3}}) {
        GhostSettings s = dfsphSettings();
        s.dfsph.densityError = Real(c.error);
        s.dfsph.maxTimeStep = Real(c.maxDt);
        s.dfsph.maxIterations = c.maxIterations;
        GhostSolver solver(s);
        solver.addSolid(scene.tank);
        solver.addLiquid(scene.water);
        double maxSpeed = 0, meanError = 0;
        while (solver.time() < 0.3) {
            solver.step(solver.stableTimeStep());
            meanError += solver.pressureSolveStats().lastDensityError;
            for (const Vec3& v : solver.particles().velocities())
                maxSpeed = std::max(maxSpeed, double(v.length()));
        }
        const PressureSolveStats& st = solver.pressureSolveStats();
        meanError /= double(st.steps);
        double outside = 0;
        for (std::size_t i = 0; i < solver.particles().size(); ++i) {
            if (solver.particles().kinds()[i] != ParticleKind::Liquid) continue;
            outside = std::min(outside, double(scene.tank.phi(solver.particles().positions()[i])));
        }
        std::printf("[measured] dfsph extremes: limit %.0e, max dt %.0e s, cap %d: %llu steps, "
                    "%.1f + %.1f iterations per step, mean error %.2e, unconverged %llu, max "
                    "speed %.2f m/s, deepest in wall %.1e m\n",
                    c.error, c.maxDt, c.maxIterations, static_cast<unsigned long long>(st.steps),
                    double(st.densityIterations) / st.steps,
                    double(st.divergenceIterations) / st.steps, meanError,
                    static_cast<unsigned long long>(st.unconverged), maxSpeed, outside);
        const double freeFall = std::sqrt(2 * 9.81 * 0.15);
        EXPECT_LT(maxSpeed, 3 * freeFall) << c.error << " " << c.maxDt;
        EXPECT_GE(outside, -0.01 * double(H)) << c.error << " " << c.maxDt;
        if (st.unconverged == 0) {
            EXPECT_LE(meanError, c.error) << c.error << " " << c.maxDt;
        }
        if (c.maxIterations < 10) {
            EXPECT_GT(st.unconverged, 0u);
        }
    }
}

// A collapse like the one above at 5 mm spacing and CFL 0.1, a quarter of the default step.
// Small steps are where the solves' limits (on one step's density change) hold after the warm
// start alone: applied whole, the last step's pressure was applied again and again with no
// iteration to renew it, and the liquid ran away (measured: 22 m/s and dt at dfsph.min_dt,
// 1e-5 s, within 0.06 s). The density solve now applies the line-searched share of it
// (DfsphPressure.cc). Asserted as for the extremes above: speed below 3 x the column's free-fall
// speed, no liquid in the walls, and the steps those of CFL 0.1 at about that speed (dt above
// a tenth of 0.1 h / 1.7 m/s). Measured: 1.14 m/s, smallest dt 2.7e-4 s, 90 steps.
TEST(Dfsph, SmallCflStepsStayBounded)
{
    const Real h = H / 2;
    const LevelSet tank =
        makeLevelSet(ghostfx::testing::closedTankGrid(
                         Vec3(0), Vec3(Real(0.3), Real(0.2), Real(0.1)), 3 * double(h), h / 2),
                     "tank");
    const LevelSet water = makeLevelSet(
        makeBoxLevelSet(Vec3(0), Vec3(Real(0.1), Real(0.15), Real(0.1)), h / 2), "water");
    GhostSettings s = dfsphSettings();
    s.spacing = h;
    s.cflNumber = Real(0.1);
    GhostSolver solver(s);
    solver.addSolid(tank);
    solver.addLiquid(water);
    double maxSpeed = 0, minDt = 1;
    int steps = 0;
    while (solver.time() < 0.06) {
        const Real dt = solver.stableTimeStep();
        minDt = std::min(minDt, double(dt));
        solver.step(dt);
        ++steps;
        for (const Vec3& v : solver.particles().velocities())
            maxSpeed = std::max(maxSpeed, double(v.length()));
    }
    double outside = 0;
    for (std::size_t i = 0; i < solver.particles().size(); ++i) {
        if (solver.particles().kinds()[i] != ParticleKind::Liquid) continue;
        outside = std::min(outside, double(tank.phi(solver.particles().positions()[i])));
    }
    const PressureSolveStats& st = solver.pressureSolveStats();
    std::printf("[measured] dfsph CFL 0.1: %d steps to 0.06 s, smallest dt %.2e s, %.1f + %.1f "
                "iterations per step, max speed %.2f m/s, deepest in wall %.1e m\n",
                steps, minDt, double(st.densityIterations) / st.steps,
                double(st.divergenceIterations) / st.steps, maxSpeed, outside);
    const double freeFall = std::sqrt(2 * 9.81 * 0.15);
    EXPECT_LT(maxSpeed, 3 * freeFall);
    EXPECT_GE(outside, -0.01 * double(H));
    EXPECT_GT(minDt, 0.1 * 0.1 * double(h) / freeFall);
}

// The tomato's tap without the tomato at 5 mm spacing: an 8 x 8 x 3 cm nozzle pouring 1 m/s
// downwards under gravity for 0.1 s, at the default CFL 0.4 and at CFL 0.1. The new particles
// carry density errors of tens of percent; with the relaxation's whole share at the small
// steps and the warm start applied whole, the CFL 0.1 stream ran away (a particle at 18.6 m/s,
// dt at dfsph.min_dt, past 300 s here; bench/history/diary-2026-11.md, "DFSPH at small steps"). Run
// at [SB12]'s 3 h support and at 2.5 h, where the pressure's acceleration in the step's force
// limit would shrink the steps from 1 ms to 10 us and throw a particle at 8.8 m/s
// (bench/history/diary-2026-11.md, "DFSPH: the pressure out of the step's force limit").
// Asserted: the CFL 0.1 run pours what the CFL 0.4 run pours within 5 % (a step-size
// property; Emitter.TapUnderGravityPoursItsRateAtAnyStep checks the rate itself), and no
// particle faster than 1.5 x the free-fall speed 1 m/s + g t. Measured since the fills are
// paid from the emitter's rate (2026-11-30): 3 h: 5,445 against 5,434 particles (+0.2 %; in
// mass +7.5 % over the nozzle's volume and 6.4 L/s, nearly all of it the first fill's surface
// layer: the body sampler puts particles on the nozzle's faces), 1.96 m/s; 2.5 h: 5,485
// against 5,477, 2.00 m/s. Before: 5,908 against 5,830 (+16.7 / +15.1 % in mass).
TEST(Dfsph, AnEmitterAtSmallCflStepsPoursAsAtTheDefaultStep)
{
    const Real h = H / 2;
    const double duration = 0.1;
    auto pour = [&](Real support, Real cfl, double& maxSpeed) {
        GhostSettings s = dfsphSettings();
        s.spacing = h;
        s.supportFactor = support;
        s.cflNumber = cfl;
        s.seed = 1;
        GhostSolver solver(s);
        ghostfx::testing::addTap(solver, h);
        maxSpeed = 0;
        ghostfx::testing::runFor(solver, duration, [&] {
            for (const Vec3& v : solver.particles().velocities())
                maxSpeed = std::max(maxSpeed, double(v.length()));
        });
        const double liquid = double(solver.count(ParticleKind::Liquid));
        const double poured = liquid * double(solver.particleMass());
        const double nominal = 1000 * (0.08 * 0.08 * 0.03 + 0.08 * 0.08 * 1.0 * solver.time());
        std::printf("[measured] dfsph tap at %.1f h support, CFL %.1f: %.0f liquid at %.3f s, "
                    "%.3f kg against the nozzle's %.3f kg (%+.1f %%), max speed %.2f m/s\n",
                    double(support), double(cfl), liquid, double(solver.time()), poured, nominal,
                    100 * (poured / nominal - 1), maxSpeed);
        return liquid;
    };
    for (const Real support : {Real(3), Real(2.5)}) {
        SCOPED_TRACE(support);
        double speedDefault = 0, speedSmall = 0;
        const double atDefault = pour(support, Real(0.4), speedDefault);
        const double atSmall = pour(support, Real(0.1), speedSmall);
        EXPECT_NEAR(atSmall / atDefault, 1.0, 0.05);
        EXPECT_LT(speedSmall, 1.5 * (1.0 + 9.81 * duration));
    }
}

// One particle of a still lattice block (zero gravity, 4,096 particles) starts 0.4 h from the
// particle below it and moving into it at 5 m/s. Its error is several percent, yet the mean over
// the block stays within the 0.1 % limit: a solve that stops on the mean alone lets it go
// (SPlisHSPlasH's dam break at 100k blew up so, bench/history/diary-2026-11.md, "DFSPH: a peak
// limit"). Asserted: no particle's error above the peak limit, 30 x 0.1 % = 3 % (DfsphSettings::
// PEAK_FACTOR). Measured: 2.93 % / 2.68 % (density / divergence); with the peak limit off the
// first divergence solve ran no iteration and left 5.76 %.
TEST(Dfsph, OneParticleDrivenIntoItsNeighbourIsStoppedThoughTheMeanIsMet)
{
    GhostSettings s = dfsphSettings();
    s.gravity = Vec3(0);
    std::vector<Vec3> still;
    Vec3 kicked(0);
    const int n = 16;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            for (int k = 0; k < n; ++k) {
                const Vec3 x = Vec3(Real(i), Real(j), Real(k)) * H;
                if (i == n / 2 && j == n / 2 && k == n / 2) kicked = x - Vec3(0, Real(0.4) * H, 0);
                else still.push_back(x);
            }
        }
    }
    GhostSolver solver(s);
    solver.addLiquidParticles(still);
    solver.addLiquidParticles({kicked}, Vec3(0, -5, 0));
    // Fixed steps of 2 ms: a CFL step would shorten with the speed and keep the error near
    // cfl times a kernel-gradient factor, about 2 %, below the peak limit.
    for (int step = 0; step < 3; ++step) solver.step(Real(2e-3));
    const PressureSolveStats& stats = solver.pressureSolveStats();
    std::printf("[measured] driven particle: largest error of one particle %.2e (density) / %.2e "
                "(divergence), %llu + %llu iterations over 3 steps, %llu unconverged\n",
                stats.largestDensityError, stats.largestDivergenceError,
                (unsigned long long)stats.densityIterations,
                (unsigned long long)stats.divergenceIterations,
                (unsigned long long)stats.unconverged);
    EXPECT_LE(stats.largestDensityError, 0.03);
    EXPECT_LE(stats.largestDivergenceError, 0.03);
    EXPECT_EQ(stats.unconverged, 0u);
}

TEST(Dfsph, ZeroGravityCubeKeepsItsShape)
{
    // [SB12] Fig. 4's test (test_hydrostatic_cube.cc): a 20 cm cube of liquid at 2.5 cm
    // spacing without gravity, 2 s. With ghost air around it the surface particles have a full
    // neighbourhood and nothing pulls the cube apart or into a ball. The cube starts from the
    // raw Poisson samples (no initial relaxation): their density errors of a few percent are
    // what the solve has to settle (from a relaxed start, beta times the error is below the
    // solve's limit and, in the double build, nothing moves at all). Bounds as the Tait
    // test's: radius of gyration within 4 %, speeds over the second second below 0.6 m/s
    // (measured +0.32 %, 0.032 m/s float on 2026-11-28, earlier +1.67 %, 0.090 m/s; double
    // +1.74 %, 0.043 m/s; Tait from the same samples through the command line: +5.1 %,
    // 5.4 m/s).
    const auto [change, lateSpeed] = zeroGravityCube(GhostSettings().supportFactor);
    EXPECT_LT(std::abs(change), 0.04);
    EXPECT_LT(lateSpeed, 0.6);
}

TEST(Dfsph, ZeroGravityCubeAtTwoSpacingsSupportKeepsItsShape)
{
    // The same cube with kernel_support 2, which tears the Tait cube apart (docs/study.md,
    // "Ghost SPH's own parameters": 4.5-134 spacings): the implicit pressure holds it. Measured
    // -0.74 %, 0.039 m/s (float); bounds as at 3 h.
    const auto [change, lateSpeed] = zeroGravityCube(Real(2));
    EXPECT_LT(std::abs(change), 0.04);
    EXPECT_LT(lateSpeed, 0.6);
}

TEST(Dfsph, LiquidHangsUnderACeiling)
{
    // The cohesion test of test_cohesion.cc with the implicit pressure: a 4 cm slab filling
    // the top of an upside-down cup. A gap opening at the ceiling is a density deficit the
    // solve pulls shut (negative pressure: no clamping), through the ceiling's ghosts. As the
    // liquid's mirror images (DfsphSettings::WallPressure::Mirror) they pull with the
    // tension the slab needs, and it hangs: over six sample realisations (seeds 1-6) the top
    // layer moved -0.9 to +0.3 mm in 0.1 s (free fall 4.9 cm; the Tait step holds it within
    // 0.4 mm). Pulling with the particle's own pressure term once (WallPressure::Own) the
    // ceiling holds the top layer with half the force the layer
    // below pulls it down with: it slides 1.5-1.7 cm, the layers packing together under
    // tension (bench/history/diary-2026-11.md, "DFSPH: ghost solids as mirror images"; 1.16 cm in
    // the double build). Bounds: 3 mm mirrored, and more than half a spacing with the own term
    // (that the test tells the two apart).
    auto drop = [](DfsphSettings::WallPressure wall) {
        GhostSettings s = dfsphSettings();
        s.seed = 4;
        s.dfsph.wallPressure = wall;
        GhostSolver solver(s);
        solver.addSolid(makeLevelSet(ghostfx::testing::invertedCupGrid(H), "cup"));
        solver.addLiquid(makeLevelSet(ghostfx::testing::ceilingSlabGrid(H), "slab"));
        auto topLayer = [&] { return ghostfx::testing::topLayerHeight(solver.particles()); };
        const double start = topLayer();
        while (solver.time() < 0.1) solver.step(solver.stableTimeStep());
        const double d = start - topLayer();
        std::printf("[measured] dfsph cohesion, %s walls: top layer dropped %.4f m in %.2f s "
                    "(free fall %.4f m), %llu steps\n",
                    wall == DfsphSettings::WallPressure::Mirror ? "mirrored" : "own-pressure", d,
                    solver.time(), 0.5 * 9.81 * 0.1 * 0.1,
                    static_cast<unsigned long long>(solver.stepCount()));
        return d;
    };
    EXPECT_LT(std::abs(drop(DfsphSettings::WallPressure::Mirror)), 0.3 * double(H));
    EXPECT_GT(drop(DfsphSettings::WallPressure::Own), 0.5 * double(H));
}

TEST(Dfsph, SettingsAreValidatedWithFieldAndValue)
{
    GhostSettings s = dfsphSettings();
    s.dfsph.densityError = 0;
    EXPECT_THROW(GhostSolver{s}, ValueError);
    s = dfsphSettings();
    s.dfsph.maxTimeStep = Real(1e-6); // below the minimum step
    EXPECT_THROW(GhostSolver{s}, ValueError);
    s = dfsphSettings();
    s.method = Method::Basic;
    try {
        GhostSolver solver(s);
        ADD_FAILURE() << "basic + dfsph accepted";
    } catch (const ValueError& e) {
        EXPECT_THAT(e.what(), ::testing::HasSubstr("pressure = 'dfsph' with method 'basic'"));
    }
    EXPECT_EQ(pressureFromName("dfsph"), PressureModel::Dfsph);
    EXPECT_THROW(pressureFromName("iisph"), ValueError);
}
