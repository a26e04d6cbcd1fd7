/// @file   test_gas_solver.cc
/// @brief  Fast SPH gas [RYY15]: density correction (Eq. 8), a block holding together against
///         the uncorrected ablation (Fig. 4a vs 4c), buoyancy and heat conservation (Eqs. 15, 17),
///         the ambient-air baseline against the fast solver (Fig. 4a vs 4b), extremes, resume and
///         thread-count determinism. Every test prints its measurements as "[measured]" lines.
#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/Random.h>

#include "common/StateDiff.h"

#include "common/Expect.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::gas;

namespace {

constexpr Real S = Real(0.02);   // particle spacing (m); support radius 2 S
constexpr Real HALF = Real(0.1); // half edge of the test blocks (m): 10 spacings across
constexpr Real TAMB = Real(293.15);

double seconds(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// [RYY15] as published: these tests check its equations and claims, without the turbulence
/// model (tests/gas/test_gas_entrainment.cc has its own).
GasSettings settingsFor(Method method)
{
    GasSettings s;
    s.method = method;
    s.turbulence = Turbulence::None;
    s.spacing = S;
    s.seed = 3;
    // dt = 1/120 s: acoustic CFL sqrt(kappa) dt / S = 0.42 at the default kappa.
    s.substeps = 4;
    return s;
}

const LevelSet& blockLevelSet()
{
    static const LevelSet block =
        makeLevelSet(makeBoxLevelSet(Vec3(-HALF), Vec3(HALF), S / 2), "block");
    return block;
}

/// Distance (m) of x inside the test block's faces (the narrow band clamps phi at 3 voxels).
Real depthInBlock(const Vec3& x)
{
    return HALF - std::max({std::abs(x[0]), std::abs(x[1]), std::abs(x[2])});
}

struct Spread
{
    double rms = 0; ///< RMS distance of gas particles from their centroid (m)
    double nn = 0;  ///< mean nearest-neighbour distance (m), capped at 3 S
    Vec3d centroid{0.0};
};

Spread measureSpread(const ParticleSet& p)
{
    std::vector<Vec3> x;
    Spread s;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Gas) continue;
        x.push_back(p.positions()[i]);
        s.centroid += Vec3d(p.positions()[i]);
    }
    if (x.empty()) return s;
    s.centroid /= double(x.size());
    NeighborGrid grid(Real(3) * S);
    grid.build(x);
    for (std::size_t i = 0; i < x.size(); ++i) {
        s.rms += (Vec3d(x[i]) - s.centroid).lengthSqr();
        double nn = 3 * S;
        grid.forEachNeighbor(Index(i), [&](Index j, const Vec3&, Real r) {
            if (j != i) nn = std::min(nn, double(r));
        });
        s.nn += nn;
    }
    s.rms = std::sqrt(s.rms / double(x.size()));
    s.nn /= double(x.size());
    return s;
}

/// Heat relative to ambient, sum_i m_i (T_i - T_ambient) over gas (J/(J/(kg K)) = kg K), in double.
double heat(const GasSolver& solver)
{
    const ParticleSet& p = solver.particles();
    const auto& T = p.scalarChannel(channel::TEMPERATURE);
    double q = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Gas) q += double(p.masses()[i]) * (double(T[i]) - TAMB);
    }
    return q;
}

using ghostfx::testing::firstDifference;
using ghostfx::testing::sameBytes;

} // namespace

// 1. Density correction, Eqs. 5, 7, 8 ---------------------------------------------------------------

TEST(GasDensity, VirtualParticleCorrectionShrinksTheSurfaceShortfall)
{
    // One step of 1 us: the densities of the block as sampled. Outer layer: particles within a
    // quarter spacing of a face (the surface samples); interior: deeper than one support radius.
    double outerBar = 0, outer = 0, innerBar = 0, inner = 0, nOuter = 0, nInner = 0;
    double outerN = 0, innerN = 0, innerAbove = 0;
    GasSolver solver(settingsFor(Method::Fast));
    solver.addGas(blockLevelSet(), Vec3(0), TAMB);
    solver.step(Real(1e-6));
    const ParticleSet& p = solver.particles();
    const auto& rhoBar = p.scalarChannel(channel::DENSITY_UNCORRECTED);
    const auto& normal = p.vectorChannel(channel::NORMAL);
    const Real R = solver.settings().supportRadius();
    const Real rho0 = solver.settings().restDensity;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Real d = depthInBlock(p.positions()[i]);
        const double nh = double(normal[i].length() * R);
        if (d < Real(0.25) * S) {
            outerBar += rhoBar[i];
            outer += p.densities()[i];
            outerN += nh;
            ++nOuter;
        } else if (d > R) {
            innerBar += rhoBar[i];
            inner += p.densities()[i];
            innerN += nh;
            ++nInner;
            innerAbove += nh > solver.settings().normalThreshold;
        }
    }
    const double shortBar = 1 - outerBar / nOuter / rho0, shortCorr = 1 - outer / nOuter / rho0;
    std::printf("[measured] density correction: %zu particles, outer layer %.0f: rho_bar/rho0 = "
                "%.3f, corrected %.3f (shortfall %.1f%% -> %.1f%%); interior %.0f: rho_bar/rho0 = "
                "%.3f, corrected %.3f; |n|h outer %.2f, interior %.2f (%.0f%% of interior above "
                "C_N = %.2f)\n",
                p.size(), nOuter, outerBar / nOuter / rho0, outer / nOuter / rho0, 100 * shortBar,
                100 * shortCorr, nInner, innerBar / nInner / rho0, inner / nInner / rho0,
                outerN / nOuter, innerN / nInner, 100 * innerAbove / nInner,
                double(solver.settings().normalThreshold));
    ASSERT_GT(nOuter, 100);
    ASSERT_GT(nInner, 20);
    // A surface sample misses the air half of its neighbourhood: measured 12.3-15.3 % short
    // over sample seeds 3-8 (float build). A poly6 half space alone would give 50 %; the
    // sampler packs the surface layer densely. Bound: 10 %.
    EXPECT_GT(shortBar, 0.10);
    // Eq. 8 removes most of it, overshooting a little: measured -0.5 to -4.2 % over seeds 3-8
    // (float), at most 0.34 of the uncorrected shortfall; bound one half.
    EXPECT_LT(std::abs(shortCorr), 0.5 * shortBar);
    // The price: the interior, where sum_j V_j grad W_ij is only statistically zero, is raised
    // by V_0 W_ik too. Measured +7.5 % (float), +7.3 % (double); bound 12 %.
    EXPECT_LT(inner / innerBar, 1.12);
    // The outer layer's normal is well above the interior noise (the basis of C_N).
    EXPECT_GT(outerN / nOuter, 2 * innerN / nInner);
}

// 2. A block holds together; the ablation scatters ([RYY15] Fig. 4a vs 4c) -------------------------

TEST(GasBlock, CompensatedBlockHoldsTogetherUncorrectedExpands)
{
    // The block is released at 25 % over rest density (gas just emitted under pressure). The
    // fast solver's atmospheric pressure (Eq. 13) stops the expansion once the surface pressure
    // balances it; without compensation nothing stops the gas expanding into the vacuum.
    const Real overpressureMass = [] {
        GasSolver probe(settingsFor(Method::Fast));
        probe.addGas(blockLevelSet(), Vec3(0), TAMB);
        probe.step(Real(1e-6));
        return probe.particleMass() * Real(1.25);
    }();
    constexpr int FRAMES = 60; // 2 s
    double growth[2][2] = {};
    for (int pressured = 0; pressured < 2; ++pressured) {
        for (const Method method : {Method::Fast, Method::Uncorrected}) {
            GasSettings s = settingsFor(method);
            if (pressured) s.particleMass = overpressureMass;
            GasSolver solver(s);
            solver.addGas(blockLevelSet(), Vec3(0), TAMB);
            const Spread s0 = measureSpread(solver.particles());
            const auto t0 = std::chrono::steady_clock::now();
            double half = 0;
            for (int f = 0; f < FRAMES; ++f) {
                solver.advanceFrame();
                if (f == FRAMES / 2 - 1) half = measureSpread(solver.particles()).rms / s0.rms;
            }
            const Spread s1 = measureSpread(solver.particles());
            growth[pressured][method == Method::Uncorrected] = s1.rms / s0.rms;
            std::printf("[measured] block %s, %s: RMS radius x%.3f after 1 s, x%.3f after 2 s; "
                        "mean nearest neighbour %.4f -> %.4f m; %zu particles, %.2f s\n",
                        pressured ? "at 1.25 rho0" : "at rho0", methodName(method), half,
                        s1.rms / s0.rms, s0.nn, s1.nn, solver.count(ParticleKind::Gas),
                        seconds(t0));
        }
    }
    std::printf("[measured] block at 1.25 rho0: uncorrected / fast RMS growth = %.2f\n",
                growth[1][1] / growth[1][0]);
    // At rest both stay within a few per cent (measured over sample seeds 3-8: fast
    // 0.975-0.985, uncorrected 1.059-1.075: the clamped Eq. 11 lets the uncorrected surface
    // relax outwards until rho <= rho0).
    EXPECT_NEAR(growth[0][0], 1.0, 0.05);
    EXPECT_LT(growth[0][1], 1.10);
    // Under pressure the compensated block grows by its compression only, (1.25 / (1 + P_a /
    // (2 kappa rho0)))^(1/3) = 1.07, measured 1.063-1.096; bound 1.12.
    EXPECT_LT(growth[1][0], 1.12);
    // The ablation expands well past that (measured 1.39-1.45 after 2 s, still growing);
    // bound 1.3.
    EXPECT_GT(growth[1][1], 1.3);
}

// 3. Buoyancy (Eq. 17) and heat conservation by diffusion (Eq. 15) ------------------------------

TEST(GasTemperature, HotBlobRisesColdStaysAndDiffusionConservesHeat)
{
    const LevelSet blob = makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.08), S / 2), "blob");
    constexpr int FRAMES = 30; // 1 s
    double rise[2] = {};
    for (int hot = 0; hot < 2; ++hot) {
        GasSettings s = settingsFor(Method::Fast);
        if (!hot) s.buoyancy = 0;
        GasSolver solver(s);
        solver.addGas(blob, Vec3(0), TAMB + Real(100));
        const Vec3d c0 = measureSpread(solver.particles()).centroid;
        for (int f = 0; f < FRAMES; ++f) solver.advanceFrame();
        const Vec3d c1 = measureSpread(solver.particles()).centroid;
        rise[hot] = c1[1] - c0[1];
        std::printf("[measured] blob %s: centroid moved (%.4f, %.4f, %.4f) m in 1 s\n",
                    hot ? "hot, C_b = 0.0335" : "hot, C_b = 0", c1[0] - c0[0], c1[1] - c0[1],
                    c1[2] - c0[2]);
    }
    // Hot: a = C_b dT = 3.35 m/s^2 at first; the boundary damping (Eq. 14, terminal speed
    // C_b dT / C_d = 0.48 m/s on the surface at the default C_d = 7 /s) and radiation (Eq. 16)
    // slow it. Measured 0.50 m (1.33 m with C_d = 1); free fall upwards would give 1.7 m.
    // Bound: more than 0.3 m (about twice the blob's diameter), less than 1.7 m.
    EXPECT_GT(rise[1], 0.3);
    EXPECT_LT(rise[1], 1.7);
    // Without buoyancy nothing moves it: measured below 1 mm; bound 5 mm.
    EXPECT_LT(std::abs(rise[0]), 0.005);

    // Heat: half the block hot, half at ambient; diffusion on, radiation and buoyancy off.
    GasSettings s = settingsFor(Method::Fast);
    s.radiationTime = 0;
    s.buoyancy = 0;
    // D_c = 0.005 kg/(m s): diffusivity 0.0025 m^2/s, explicit limit s^2 rho0 / (3 D_c) =
    // 0.027 s > dt = 1/120 s. (D_c = 0.05 is past the limit: the blow-up check stops it.)
    s.diffusion = Real(0.005);
    GasSolver solver(s);
    solver.addGas(blockLevelSet(), Vec3(0), TAMB);
    auto& T = solver.particles().scalarChannel(channel::TEMPERATURE);
    for (std::size_t i = 0; i < T.size(); ++i) {
        if (solver.particles().positions()[i][0] > 0) T[i] = TAMB + Real(100);
    }
    auto spreadT = [&] {
        double sum = 0, sum2 = 0, n = 0;
        for (std::size_t i = 0; i < T.size(); ++i) {
            sum += T[i];
            sum2 += double(T[i]) * T[i];
            ++n;
        }
        return std::sqrt(std::max(0.0, sum2 / n - sqr(sum / n)));
    };
    solver.step(Real(1e-6)); // sets the particle mass
    const double q0 = heat(solver), sd0 = spreadT();
    for (int f = 0; f < FRAMES; ++f) solver.advanceFrame();
    const double q1 = heat(solver), sd1 = spreadT();
    std::printf("[measured] diffusion only: heat %.6e -> %.6e kg K (relative change %.2e), "
                "temperature std %.1f -> %.1f K, %zu particles\n",
                q0, q1, (q1 - q0) / q0, sd0, sd1, solver.count(ParticleKind::Gas));
    // Eq. 15 is antisymmetric in i, j, so heat changes only by float rounding of T += dt dT/dt
    // (T ~ 400 K, float epsilon 6e-8, 120 steps): bound 1e-4 relative.
    EXPECT_LT(std::abs(q1 - q0) / q0, 1e-4);
    // And diffusion does act: the temperature spread falls (measured 50 -> 30 K; bound: by a
    // tenth).
    EXPECT_LT(sd1, 0.9 * sd0);
}

// 5. The ambient-air baseline and the fast solver: a plume from a source ([RYY15] Fig. 4) -----

TEST(GasPlume, AmbientBaselineAndFastSolverRiseAlikeWithFarFewerParticles)
{
    const Real s = Real(0.025);
    const Aabb domain{Vec3(-0.2f, 0.0f, -0.2f), Vec3(0.2f, 0.6f, 0.2f)};
    const Vec3 sourceCentre(0, Real(0.08), 0);
    const LevelSet nozzle =
        makeLevelSet(makeSphereLevelSet(sourceCentre, Real(0.05), s / 2), "source");
    constexpr int FRAMES = 24; // 0.8 s
    double top[2] = {}, cost[2] = {}, visible[2] = {}, simulated[2] = {};
    for (const Method method : {Method::Ambient, Method::Fast}) {
        GasSettings gs = settingsFor(method);
        gs.spacing = s;
        gs.substeps = 3; // dt = 1/90 s: acoustic CFL 0.44
        gs.domain = domain;
        // Heat stays in the visible gas in both (no diffusion into the air, no radiation), so
        // the two differ only in what the paper changes: air particles against compensation.
        gs.diffusion = 0;
        gs.radiationTime = 0;
        // A thin gas (mu 0.002 Pa s); the fast solver stands in for the air's drag with the
        // damping of Eq. 14, a user coefficient ([RYY15] gives no value): the default C_d = 7 /s
        // matches the baseline here (measured: C_d = 5 rises 1.25x, 10 rises 0.85x the
        // baseline's height).
        gs.viscosity = Real(0.002);
        GasSolver solver(gs);
        GasSource src;
        src.temperature = TAMB + Real(100);
        solver.addSource(nozzle, src);
        const auto t0 = std::chrono::steady_clock::now();
        std::size_t peak = 0;
        for (int f = 0; f < FRAMES; ++f) {
            solver.advanceFrame();
            peak = std::max(peak, solver.count(ParticleKind::Gas));
        }
        const int k = method == Method::Fast;
        cost[k] = seconds(t0);
        // Plume top: the 95th percentile height of the visible gas above the source centre.
        const ParticleSet& p = solver.particles();
        const std::vector<Real>* ambient =
            p.hasScalarChannel(channel::AMBIENT) ? &p.scalarChannel(channel::AMBIENT) : nullptr;
        std::vector<Real> heights;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Gas || (ambient && (*ambient)[i] != 0)) continue;
            heights.push_back(p.positions()[i][1] - sourceCentre[1]);
        }
        ASSERT_FALSE(heights.empty());
        std::sort(heights.begin(), heights.end());
        top[k] = heights[heights.size() * 95 / 100];
        visible[k] = double(heights.size());
        simulated[k] = double(peak);
        std::printf("[measured] plume %s: top %.3f m above the source after 0.8 s, %zu visible, "
                    "%zu simulated particles (+%zu boundary), %.2f s wall\n",
                    methodName(method), top[k], heights.size(), solver.count(ParticleKind::Gas),
                    solver.count(ParticleKind::Boundary), cost[k]);
    }
    std::printf("[measured] plume: fast / ambient top = %.2f, ambient / fast simulated particles = "
                "%.1f, wall time ambient / fast = %.1f, visible fast / ambient = %.2f\n",
                top[1] / top[0], simulated[0] / simulated[1], cost[0] / cost[1],
                visible[1] / visible[0]);
    // Similar rise: within 30 % of each other (the fast solver replaces the air's drag by the
    // boundary damping of Eq. 14, a model, not the same physics).
    EXPECT_NEAR(top[1] / top[0], 1.0, 0.30);
    // Far fewer particles: the whole box of air against the plume only (measured 29x, wall
    // time 10x; the paper reports 25 - 400x fewer particles in larger scenes).
    EXPECT_GT(simulated[0] / simulated[1], 5.0);
}

// 7. Extremes, isolated particles, resume, determinism ----------------------------------------------

TEST(GasExtremes, KappaOverEightOrdersNeverGivesSilentNaN)
{
    int blowUps = 0;
    for (const Real kappa : {Real(1e-4), Real(1), Real(1e4)}) {
        for (const Method method : {Method::Fast, Method::Uncorrected}) {
            GasSettings s = settingsFor(method);
            s.kappa = kappa;
            GasSolver solver(s);
            solver.addGas(blockLevelSet(), Vec3(0), TAMB + Real(50));
            const std::size_t count0 = solver.count(ParticleKind::Gas);
            const double y0 = measureSpread(solver.particles()).centroid[1];
            std::string error;
            try {
                for (int f = 0; f < 10; ++f) solver.advanceFrame();
            } catch (const NumericalError& e) {
                error = e.what();
                ++blowUps;
            }
            double vmax = 0;
            bool finite = true;
            for (std::size_t i = 0; i < solver.particles().size(); ++i) {
                vmax = std::max(vmax, double(solver.particles().velocities()[i].length()));
            }
            if (error.empty()) {
                for (std::size_t i = 0; i < solver.particles().size(); ++i) {
                    finite = finite && isFinite(solver.particles().positions()[i])
                             && isFinite(solver.particles().velocities()[i])
                             && std::isfinite(solver.particles().densities()[i]);
                }
                EXPECT_TRUE(finite) << "silent NaN at kappa " << kappa;
                // A run that finishes must be plausible (issue 18). Buoyancy (Eq. 17) gives
                // every particle a = C_b dT = 1.68 m/s^2 up; undamped, the block would rise
                // a t^2 / 2 = 9.3 cm in the 1/3 s and reach a t = 0.56 m/s. Measures: the
                // centroid rises between a quarter and 1.1 x that (boundary damping and
                // viscosity only slow it), no particle exceeds 3 x a t, and the block keeps
                // its particles (isolated-particle removal may take a few: 95 %).
                const double t = solver.time(), a = double(s.buoyancy) * 50;
                const double freeRise = 0.5 * a * t * t;
                const double rise = measureSpread(solver.particles()).centroid[1] - y0;
                const std::size_t count = solver.count(ParticleKind::Gas);
                std::printf("[measured] kappa %g %s: centroid rise %.4f m (%.2f x free rise), "
                            "%zu of %zu particles\n",
                            double(kappa), methodName(method), rise, rise / freeRise, count,
                            count0);
                EXPECT_GT(rise, 0.25 * freeRise) << "kappa " << kappa;
                EXPECT_LT(rise, 1.1 * freeRise) << "kappa " << kappa;
                EXPECT_LT(vmax, 3 * a * t) << "kappa " << kappa;
                EXPECT_GE(double(count), 0.95 * double(count0)) << "kappa " << kappa;
            } else {
                EXPECT_NE(error.find("blew up at frame"), std::string::npos) << error;
                EXPECT_NE(error.find("particle id"), std::string::npos) << error;
                EXPECT_NE(error.find("reduce the time step"), std::string::npos) << error;
            }
            std::printf("[measured] kappa %g %s: %s, max speed %.3g m/s\n", double(kappa),
                        methodName(method), error.empty() ? "ran 10 frames" : error.c_str(), vmax);
        }
    }
    // kappa = 1e4 (sound speed 100 m/s) at dt = 1/120 s is CFL 420: the detector must fire.
    EXPECT_GE(blowUps, 1);

    // The CFL-adaptive stepper takes the stiff gas's steps (sound speed 100 m/s), but the block
    // flies apart from its sampled start (median density 0.36 rho0 and median speed 4.4 m/s
    // after one frame, every step inside the speed limit): it must stop with the error that
    // says so, not finish as an explosion.
    GasSettings s = settingsFor(Method::Fast);
    s.kappa = Real(1e4);
    s.substeps = 0;
    GasSolver solver(s);
    solver.addGas(blockLevelSet(), Vec3(0), TAMB + Real(50));
    std::string error;
    try {
        for (int f = 0; f < 4; ++f) solver.advanceFrame();
    } catch (const NumericalError& e) {
        error = e.what();
    }
    std::printf("[measured] kappa 1e4 CFL-adaptive: %llu steps, %s\n",
                static_cast<unsigned long long>(solver.stepCount()),
                error.empty() ? "finished" : error.c_str());
    EXPECT_GT(solver.stepCount(), 100u);
    EXPECT_NE(error.find("the gas is flying apart, its median density is 0."), std::string::npos)
        << error;
    EXPECT_NE(error.find("reduce kappa"), std::string::npos) << error;
}

TEST(GasExtremes, IsolatedParticlesLoseTheirLifeStrength)
{
    GasSettings s = settingsFor(Method::Fast);
    s.lifeStrength = Real(0.2);
    GasSolver solver(s);
    solver.addGas(blockLevelSet(), Vec3(0), TAMB);
    const std::size_t block = solver.count(ParticleKind::Gas);
    // Three strays far from the block and from each other.
    solver.addParticles({Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, Vec3(0), TAMB);
    solver.advanceFrame(); // 0.033 s: all alive
    EXPECT_EQ(solver.count(ParticleKind::Gas), block + 3);
    for (int f = 0; f < 8; ++f) solver.advanceFrame(); // 0.3 s > 0.2 s (1 + 0.1)
    std::printf("[measured] life strength 0.2 s: %zu isolated removed after 0.3 s, %zu left\n",
                solver.isolatedRemovedCount(), solver.count(ParticleKind::Gas));
    EXPECT_EQ(solver.isolatedRemovedCount(), 3u);
    EXPECT_EQ(solver.count(ParticleKind::Gas), block);

    s.lifeStrength = 0; // never removed
    GasSolver keep(s);
    keep.addParticles({Vec3(1, 0, 0), Vec3(0, 1, 0)}, Vec3(0), TAMB, Real(1e-5));
    for (int f = 0; f < 10; ++f) keep.advanceFrame();
    EXPECT_EQ(keep.count(ParticleKind::Gas), 2u);
}

namespace {

/// A scene touching every piece of state: a moving solid, a rate-limited moving source,
/// vorticity, a kill box and isolated-particle removal.
struct ResumeScene
{
    GasSettings settings;
    LevelSet floor, nozzle;

    ResumeScene()
        : floor(makeLevelSet(
            makeBoxLevelSet(Vec3(-0.15f, -0.06f, -0.15f), Vec3(0.15f, -0.02f, 0.15f), S / 2),
            "floor"))
        , nozzle(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.04), S / 2), "nozzle"))
    {
        settings = settingsFor(Method::Fast);
        settings.vorticity = true;
        settings.domain = Aabb{Vec3(-0.3f, -0.3f, -0.3f), Vec3(0.3f, 0.25f, 0.3f)};
        settings.lifeStrength = Real(0.05);
    }

    void addInputs(GasSolver& solver) const
    {
        solver.addSolid(floor, Vec3(Real(0.05), 0, 0));
        GasSource src;
        src.temperature = TAMB + Real(150);
        src.velocity = Vec3(0, Real(0.3), 0);
        src.rate = Real(3000);
        src.motion = [](double t) {
            RigidTransform xf;
            xf.translation = Vec3(Real(0.1 * t), Real(0.03), 0);
            return xf;
        };
        solver.addSource(nozzle, src);
    }
};

} // namespace

TEST(GasResume, InMemoryContinuationIsBitIdentical)
{
    const ResumeScene scene;
    GasSolver whole(scene.settings);
    scene.addInputs(whole);
    whole.addParticles({Vec3(0.2f, 0.2f, 0.2f)}, Vec3(0), TAMB); // a stray, removed later
    for (int f = 0; f < 4; ++f) whole.advanceFrame();

    GasSolver first(scene.settings);
    scene.addInputs(first);
    first.addParticles({Vec3(0.2f, 0.2f, 0.2f)}, Vec3(0), TAMB);
    for (int f = 0; f < 2; ++f) first.advanceFrame();
    const SolverState saved = first.saveState();

    GasSolver resumed(scene.settings);
    resumed.restoreState(saved);
    scene.addInputs(resumed);
    EXPECT_EQ(resumed.particles().size(), first.particles().size()); // floor not resampled
    while (resumed.frame() < 4) resumed.advanceFrame();

    const std::string difference = firstDifference(whole.saveState(), resumed.saveState());
    std::printf("[measured] gas resume: %zu gas, %zu boundary, emitted %zu, killed %zu, isolated "
                "removed %zu, %llu steps; first difference '%s'\n",
                whole.count(ParticleKind::Gas), whole.count(ParticleKind::Boundary),
                whole.emittedCount(), whole.killedCount(), whole.isolatedRemovedCount(),
                static_cast<unsigned long long>(whole.stepCount()), difference.c_str());
    EXPECT_EQ(difference, "");
    EXPECT_GT(whole.emittedCount(), 0u);
    EXPECT_GE(whole.isolatedRemovedCount(), 1u);
    // Rate-limited: 3000 particles/s for 4 / 30 s is at most 400.
    EXPECT_LE(whole.emittedCount(), 400u);

    // The contract: another solver, a stale budget, gas after a restore.
    GasSolver wrong(ghostfx::testing::withMethod(scene.settings, Method::Ambient));
    EXPECT_THAT(ghostfx::testing::errorOf<ValueError>([&] { wrong.restoreState(saved); }),
                ::testing::HasSubstr("saved by gas method 'fast'"));
    GasSolver again(scene.settings);
    again.restoreState(saved);
    EXPECT_THROW(again.addParticles({Vec3(0)}, Vec3(0), TAMB), ValueError);
    EXPECT_THROW(again.step(Real(0.01)), ValueError); // solids and sources not added again
}

TEST(GasDeterminism, OneAndManyThreadsGiveIdenticalRuns)
{
    const ResumeScene scene;
    SolverState states[2];
    for (int k = 0; k < 2; ++k) {
        parallel::ThreadLimit limit(k == 0 ? 1 : 0);
        GasSolver solver(scene.settings);
        scene.addInputs(solver);
        solver.addGas(blockLevelSet(), Vec3(0), TAMB + Real(30));
        for (int f = 0; f < 3; ++f) solver.advanceFrame();
        states[k] = solver.saveState();
    }
    const std::string difference = firstDifference(states[0], states[1]);
    std::printf("[measured] 1 thread vs %d threads: %zu particles, first difference '%s'\n",
                parallel::maxThreads(), states[0].particles.size(), difference.c_str());
    EXPECT_EQ(difference, "");
}

TEST(GasSettingsTest, ValidationNamesTheSettingValueAndRange)
{
    GasSettings s;
    s.delta = Real(0.3);
    try {
        s.validate();
        FAIL() << "delta 0.3 must be refused";
    } catch (const ValueError& e) {
        EXPECT_NE(std::string(e.what()).find("gas setting delta = 0.3"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("a number in [0.4, 0.7]"), std::string::npos) << e.what();
    }
    s = GasSettings();
    s.method = Method::Ambient; // no domain
    EXPECT_THROW(GasSolver{s}, ValueError);
    EXPECT_EQ(methodFromName("uncorrected"), Method::Uncorrected);
    EXPECT_THROW(methodFromName("ghost"), ValueError);
}

// Attractor force field ([RYY15] Fig. 7; formula in GasSettings.h) ------------------------------

namespace {

/// Velocity change per unit time of one step from rest, per particle id, with the given
/// attractors; buoyancy and gravity off, so only the gas's own forces and the attractors act.
std::vector<Vec3> firstStepAcceleration(const LevelSet& cloud, const std::vector<Attractor>& fields,
                                        Real dt, std::vector<Vec3>* positions)
{
    GasSettings s = settingsFor(Method::Fast);
    s.buoyancy = 0;
    s.attractors = fields;
    GasSolver solver(s);
    solver.addGas(cloud, Vec3(0), TAMB);
    const std::vector<Vec3> x0 = solver.particles().positions(); // ids are 0..n-1 in this order
    solver.step(dt);
    const ParticleSet& p = solver.particles();
    std::vector<Vec3> a(x0.size(), Vec3(0));
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Gas) a[p.ids()[i]] = p.velocities()[i] / dt;
    }
    if (positions) *positions = x0;
    return a;
}

/// Mass-weighted mean (all gas particles have one mass here: the plain mean).
Vec3d mean(const std::vector<Vec3>& v)
{
    Vec3d sum(0.0);
    for (const Vec3& x : v) sum += Vec3d(x);
    return sum / double(v.size());
}

} // namespace

TEST(GasAttractor, FormulaIsContinuousFiniteAtTheCentreAndFallsOff)
{
    Attractor a;
    a.position = Vec3(1, 2, 3);
    a.strength = Real(2);
    a.radius = Real(0.5);
    EXPECT_EQ(a.acceleration(a.position), Vec3(0)); // finite (zero) at the centre
    // Core: linear, S r / R towards c.
    EXPECT_NEAR(a.acceleration(Vec3(1.25f, 2, 3))[0], -1.0, 1e-6);
    // Continuous at r = R (|a| = S from both sides), then (R / r)^2.
    EXPECT_NEAR(a.acceleration(Vec3(1.4999f, 2, 3)).length(), 2.0, 1e-3);
    EXPECT_NEAR(a.acceleration(Vec3(1.5001f, 2, 3)).length(), 2.0, 1e-3);
    EXPECT_NEAR(a.acceleration(Vec3(1, 3, 3))[1], -2.0 * 0.25, 1e-6);
    EXPECT_NEAR(a.acceleration(Vec3(1, 2, 5))[2], -2.0 / 16, 1e-6);
    a.falloff = Falloff::Constant;
    EXPECT_NEAR(a.acceleration(Vec3(1, 2, 5))[2], -2.0, 1e-6);
    a.strength = Real(-2); // repels
    EXPECT_NEAR(a.acceleration(Vec3(1, 2, 5))[2], 2.0, 1e-6);

    GasSettings s;
    s.attractors = {a};
    s.attractors[0].radius = 0;
    try {
        s.validate();
        FAIL() << "radius 0 must be refused";
    } catch (const ValueError& e) {
        EXPECT_NE(
            std::string(e.what()).find("gas setting attractors[0].radius = 0: expected a finite "
                                       "value > 0 (m)"),
            std::string::npos)
            << e.what();
    }
    EXPECT_EQ(falloffFromName("constant"), Falloff::Constant);
    EXPECT_THROW(falloffFromName("cubic"), ValueError);
}

TEST(GasAttractor, CloudAcceleratesTowardsThePointAsThePerParticleFalloffSays)
{
    // A ball of gas (radius 0.08 m, ~350 particles at 2 cm) at rest at the origin, buoyancy and
    // gravity off. One step of dt = 1 ms from rest: v_i / dt is the acceleration of each
    // particle; the run without attractor gives the gas's own part (pressure, Eqs. 10, 13), so
    // the difference is the attractor's alone and must equal the formula at the particle's
    // start position. Float: v ~ 1e-3 m/s, relative rounding 1e-7; bound 1e-4 m/s^2.
    const LevelSet cloud = makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.08), S / 2), "cloud");
    const Real dt = Real(1e-3);
    std::vector<Vec3> x;
    const std::vector<Vec3> own = firstStepAcceleration(cloud, {}, dt, &x);
    // Straddling the core: particles within R = 0.04 m of c = (0.03, 0, 0) are in the linear
    // core, the others on the inverse-square tail.
    Attractor straddle;
    straddle.position = Vec3(Real(0.03), 0, 0);
    straddle.strength = Real(2);
    straddle.radius = Real(0.04);
    const std::vector<Vec3> with = firstStepAcceleration(cloud, {straddle}, dt, nullptr);
    ASSERT_EQ(with.size(), own.size());
    double worst = 0;
    std::size_t core = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        worst = std::max(worst, double((with[i] - own[i] - straddle.acceleration(x[i])).length()));
        core += (x[i] - straddle.position).length() < straddle.radius;
    }
    std::printf("[measured] attractor per particle: %zu particles (%zu in the core), worst |a - "
                "formula| = %.2e m/s^2\n",
                x.size(), core, worst);
    EXPECT_GT(core, 20u);
    EXPECT_LT(core, x.size() - 20);
    EXPECT_LT(worst, 1e-4);

    // Centre of mass, far side (inverse square): the attractor at distance d from the ball's
    // centre, d > R + 0.08 m. By Newton's shell theorem a uniform ball feels S (R / d)^2 at its
    // centre. The gas's own forces do not sum to zero in the fast method (the virtual-particle
    // and atmospheric terms, Eqs. 10 and 13, are not pairwise antisymmetric): their mean,
    // `ownMean`, is measured from the run without attractor. Bounds: the attractor's part
    // (com - ownMean) within 3 % of the shell theorem (a Poisson sample of ~350 particles is
    // uniform to a few per cent; measured 0.1 - 0.5 %), the whole centre-of-mass acceleration
    // within that plus |ownMean|. Twice as far away: a quarter of the pull (within 3 %).
    const Vec3d ownMean = mean(own);
    double pull[2] = {};
    for (int k = 0; k < 2; ++k) {
        const double d = k == 0 ? 0.3 : 0.6;
        Attractor far;
        far.position = Vec3(Real(d), 0, 0);
        far.strength = Real(20);
        far.radius = Real(0.1);
        const Vec3d com = mean(firstStepAcceleration(cloud, {far}, dt, nullptr));
        const double expected = 20.0 * sqr(0.1 / d);
        pull[k] = com[0] - ownMean[0];
        std::printf("[measured] ball at d = %.1f m: centre-of-mass acceleration (%.4f, %.4f, %.4f) "
                    "m/s^2, of which own forces (%.4f, %.4f, %.4f); shell theorem %.4f\n",
                    d, com[0], com[1], com[2], ownMean[0], ownMean[1], ownMean[2], expected);
        EXPECT_NEAR(pull[k], expected, 0.03 * expected);
        EXPECT_NEAR(com[0], expected, 0.03 * expected + ownMean.length());
        EXPECT_LT((com - ownMean).length() - std::abs(pull[k]), 0.03 * expected);
    }
    EXPECT_NEAR(pull[1] / pull[0], 0.25, 0.03 * 0.25);

    // Near side (core): with R = 0.25 m every particle is in the linear core, so the
    // attractor's mean is exactly S (c - centroid) / R for any cloud shape (bound: float
    // rounding, 1e-3 relative).
    Attractor wide;
    wide.position = Vec3(Real(0.05), 0, 0);
    wide.strength = Real(4);
    wide.radius = Real(0.25);
    const Vec3d com = mean(firstStepAcceleration(cloud, {wide}, dt, nullptr));
    const double expected = 4.0 * (0.05 - mean(x)[0]) / 0.25;
    std::printf("[measured] ball inside the core: centre-of-mass acceleration %.5f m/s^2 (own "
                "forces %.5f), expected %.5f\n",
                com[0], ownMean[0], expected);
    EXPECT_NEAR(com[0] - ownMean[0], expected, 1e-3 * expected);
}

TEST(GasAttractor, PullsAPuffToThePointAndHoldsItThere)
{
    // A hot puff below an attractor 0.4 m up, buoyancy off: it moves up to the point and stays
    // around it (the core is a harmonic well, damped by Eq. 14 at the gas boundary).
    GasSettings s = settingsFor(Method::Fast);
    s.buoyancy = 0;
    Attractor a;
    a.position = Vec3(0, Real(0.4), 0);
    a.strength = Real(3);
    a.radius = Real(0.15);
    s.attractors = {a};
    GasSolver solver(s);
    solver.addGas(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.06), S / 2), "puff"), Vec3(0),
                  TAMB);
    for (int f = 0; f < 60; ++f) solver.advanceFrame(); // 2 s
    const Spread spread = measureSpread(solver.particles());
    std::printf("[measured] puff after 2 s: centroid (%.3f, %.3f, %.3f) m, RMS radius %.3f m, "
                "%zu particles\n",
                spread.centroid[0], spread.centroid[1], spread.centroid[2], spread.rms,
                solver.count(ParticleKind::Gas));
    // Free motion in the field would reach the point at about t = 0.5 s; the damped puff has
    // risen about two thirds of the way after 2 s, its centroid 0.127-0.151 m from the point
    // (0.85-1.01 core radii) over sample seeds 3-8. Bound: 1.2 core radii (from 2.7 at the
    // start).
    EXPECT_LT((spread.centroid - Vec3d(a.position)).length(), Real(1.2) * a.radius);
}

TEST(GasAmbient, AirFillsAroundASolidWithANarrowBand)
{
    // A boiling scene's solids are voxelised at half the liquid spacing, several times finer
    // than the vapour: their narrow band (3 voxels) is thinner than the half gas spacing new
    // gas keeps from solids. Beyond the band phi is clamped to the band width, which once read
    // as "too close" everywhere and left the ambient baseline without any air.
    GasSettings s = settingsFor(Method::Ambient);
    s.spacing = Real(0.04); // clearance 0.02 m
    s.domain = Aabb{Vec3(-0.3f), Vec3(0.3f)};
    const Real voxel = Real(0.004); // band 3 voxels = 0.012 m < 0.02 m
    GasSolver solver(s);
    solver.addSolid(makeLevelSet(makeBoxLevelSet(Vec3(-0.1f), Vec3(0.1f), voxel), "cube"));
    solver.step(Real(1e-4));
    const double boxVolume = cube(0.6 - 0.04) - cube(0.2);
    const double expected = boxVolume / cube(0.04);
    std::printf("[measured] ambient air around a narrow-band cube: %zu particles, %.0f lattice "
                "cells of the free volume\n",
                solver.ambientCount(), expected);
    // Poisson-disk sampling at radius 0.92 s packs about 0.7 - 1 particle per s^3.
    EXPECT_GT(double(solver.ambientCount()), 0.5 * expected);
    // None inside the cube or in its band.
    const ParticleSet& p = solver.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Gas) continue;
        const Vec3 x = p.positions()[i];
        EXPECT_GT(std::max({std::abs(x[0]), std::abs(x[1]), std::abs(x[2])}), 0.1 + 0.011) << x;
    }
}
