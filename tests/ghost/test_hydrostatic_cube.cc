/// @file   test_hydrostatic_cube.cc
/// @brief  [SB12] Fig. 4: a cube of liquid at rest without gravity. Ghost SPH keeps its shape,
///         volume and uniform density; Basic SPH, same particles and mass, shrinks and packs its
///         surface particles into a shell.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/NeighborGrid.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.01);    // particle spacing (m)
constexpr Real HALF = Real(0.06); // half edge of the cube (m): 12 h across
constexpr int STEPS = 300;
constexpr Real DT = Real(1) / Real(1200); // acoustic CFL c dt / h = 0.31 at k = 2000

struct CubeState
{
    double volume;       ///< SPH volume sum m / rho over liquid (m^3)
    double gyration;     ///< radius of gyration about the centre of mass (m)
    double innerDensity; ///< mean density of particles in the inner half of the cube (kg/m^3)
    double outerDensity; ///< mean density of the outer layer (kg/m^3)
    double innerSpacing; ///< mean nearest-neighbour distance, inner half (m)
    double outerSpacing; ///< mean nearest-neighbour distance, outer layer (m)
};

CubeState measure(const ParticleSet& p)
{
    std::vector<Vec3> x;
    std::vector<Real> rho, m;
    Vec3d com(0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        x.push_back(p.positions()[i]);
        rho.push_back(p.densities()[i]);
        m.push_back(p.masses()[i]);
        com += Vec3d(p.positions()[i]);
    }
    com /= double(x.size());
    CubeState s{};
    double rg = 0, nIn = 0, nOut = 0;
    NeighborGrid grid(Real(2) * H);
    grid.build(x);
    for (std::size_t i = 0; i < x.size(); ++i) {
        s.volume += double(m[i]) / double(rho[i]);
        const Vec3d d = Vec3d(x[i]) - com;
        rg += d.lengthSqr();
        double nn = 1e9;
        grid.forEachNeighbor(Index(i), [&](Index j, const Vec3&, Real r) {
            if (j != i) nn = std::min(nn, double(r));
        });
        // Box "norm" relative to the initial half edge: < 0.5 inner half, > 0.8 outer layer.
        const double q = std::max({std::abs(d.x()), std::abs(d.y()), std::abs(d.z())}) / HALF;
        if (q < 0.5) {
            s.innerDensity += rho[i];
            s.innerSpacing += nn;
            nIn += 1;
        } else if (q > 0.8 && q < 1.05) {
            s.outerDensity += rho[i];
            s.outerSpacing += nn;
            nOut += 1;
        }
    }
    s.gyration = std::sqrt(rg / double(x.size()));
    s.innerDensity /= nIn;
    s.outerDensity /= nOut;
    s.innerSpacing /= nIn;
    s.outerSpacing /= nOut;
    return s;
}

struct CubeRun
{
    CubeState start, end;
};

CubeRun runCube(Method method)
{
    GhostSettings settings;
    settings.method = method;
    settings.spacing = H;
    settings.gravity = Vec3(0);
    settings.seed = 3;
    GhostSolver solver(settings);
    solver.addLiquid(makeLevelSet(makeBoxLevelSet(Vec3(-HALF), Vec3(HALF), H / 2), "cube"));
    solver.step(DT);
    CubeRun run;
    run.start = measure(solver.particles());
    for (int s = 1; s < STEPS; ++s) solver.step(DT);
    run.end = measure(solver.particles());
    std::printf("[measured] %s: volume %.4f -> %.4f (x start), gyration %.4f -> %.4f, "
                "density inner/outer %.1f / %.1f, spacing inner/outer %.3f / %.3f h "
                "(start %.3f / %.3f h)\n",
                methodName(method), 1.0, run.end.volume / run.start.volume, 1.0,
                run.end.gyration / run.start.gyration, run.end.innerDensity, run.end.outerDensity,
                run.end.innerSpacing / H, run.end.outerSpacing / H, run.start.innerSpacing / H,
                run.start.outerSpacing / H);
    return run;
}

} // namespace

TEST(HydrostaticCube, GhostKeepsShapeVolumeAndUniformDensityWhereBasicShrinksIntoAShell)
{
    const CubeRun ghost = runCube(Method::Ghost);
    const CubeRun basic = runCube(Method::Basic);

    auto shell = [](const CubeState& c) { return c.outerSpacing / c.innerSpacing; };
    auto outerPacking = [](const CubeRun& r) { return r.end.outerSpacing / r.start.outerSpacing; };

    // Ghost SPH ([SB12] Sec. 4.3, Fig. 4 left). Measured after 300 steps: SPH volume -0.1 %,
    // gyration radius +2 to +3 % (corners round off a little), outer vs inner density 0.6 %
    // apart, outer/inner nearest-neighbour spacing ratio 0.968 -> 0.936, outer spacing 0.90 of
    // its start. Bounds: volume 2 %, gyration 6 %, densities 1.5 %, spacing ratio 8 %: over
    // 12 sample realisations (the sampler's seed salted, both volume relaxations;
    // bench/history/diary-2026-11.md, "Tests that hold over sample realisations") the ratio moved
    // by -3.0 to -6.1 %; Basic SPH's outer spacing falls by half.
    EXPECT_NEAR(ghost.end.volume / ghost.start.volume, 1.0, 0.02);
    EXPECT_NEAR(ghost.end.gyration / ghost.start.gyration, 1.0, 0.06);
    EXPECT_NEAR(ghost.end.outerDensity / ghost.end.innerDensity, 1.0, 0.015);
    EXPECT_NEAR(shell(ghost.end) / shell(ghost.start), 1.0, 0.08);

    // Basic SPH, same particles and mass ([SB12] Sec. 3, Fig. 4 right): surface particles miss
    // half their neighbours and the equation of state pulls them in. Measured: SPH volume -11 %,
    // outer-layer spacing 0.52 of its start (a packed shell; the negative pressure also pairs
    // particles inside, the tensile instability). Bounds: volume below -5 %, outer packing
    // under 0.8 of Ghost SPH's.
    EXPECT_LT(basic.end.volume / basic.start.volume, 0.95);
    EXPECT_LT(outerPacking(basic), 0.8 * outerPacking(ghost));
}

// [SB12] Fig. 4 over 2 s -------------------------------------------------------------------------
// The 300 steps above are too short to see kept ghost air accumulate: with airKeepFraction 0.8
// (the former default) the cube holds for 0.3 s and blows apart within 2 s. A coarser cube
// (8 across, 572 liquid particles) keeps this under 20 s on one core.

namespace {

constexpr Real ZG_H = Real(0.025);          // particle spacing (m): 8 across, 572 liquid particles
constexpr Real ZG_EDGE = Real(0.2);         // cube edge (m)
constexpr Real ZG_DT = Real(1) / Real(750); // acoustic CFL c dt / h = 0.2 at k = 2000
constexpr int ZG_STEPS = 1500;              // 2 s

struct Shape
{
    double gyration; ///< radius of gyration of the liquid about its centre of mass (m)
    double maxSpeed; ///< largest liquid speed (m/s)
};

Shape measureShape(const ParticleSet& p)
{
    Vec3d com(0);
    std::size_t n = 0;
    double vmax = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        com += Vec3d(p.positions()[i]);
        vmax = std::max(vmax, double(p.velocities()[i].length()));
        ++n;
    }
    com /= double(n);
    double rg = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid) rg += (Vec3d(p.positions()[i]) - com).lengthSqr();
    }
    return {std::sqrt(rg / double(n)), vmax};
}

} // namespace

namespace {

void expectCubeKeepsTogether(AirWeights weights)
{
    GhostSettings settings; // default air handling but the weights: the subject of this test
    settings.airWeights = weights;
    settings.spacing = ZG_H;
    settings.gravity = Vec3(0);
    settings.seed = 1;
    GhostSolver solver(settings);
    solver.addLiquid(makeLevelSet(makeBoxLevelSet(Vec3(0), Vec3(ZG_EDGE), ZG_H / 2), "cube"));
    solver.step(ZG_DT);
    const Shape start = measureShape(solver.particles());
    double lateSpeed = 0; // largest liquid speed over the second second (m/s)
    for (int s = 1; s < ZG_STEPS; ++s) {
        solver.step(ZG_DT);
        if (s >= ZG_STEPS / 2)
            lateSpeed = std::max(lateSpeed, measureShape(solver.particles()).maxSpeed);
    }
    const Shape end = measureShape(solver.particles());
    std::printf("[measured] zero-g cube, 2 s, %s air weights: gyration %+.2f %%, max speed over "
                "1-2 s %.3f m/s, %zu air\n",
                weights == AirWeights::Matched ? "matched" : "complete",
                100.0 * (end.gyration / start.gyration - 1.0), lateSpeed,
                solver.count(ParticleKind::GhostAir));

    // Measured (seed 1, h = 0.025, CFL-adaptive CLI run of the same scene and this fixed step):
    // replacing the whole layer, gyration radius -1 % to +1.5 % and max speed 0.17 - 0.25 m/s
    // (the resampling noise) throughout; keeping air (airKeepFraction 0.8, the former default),
    // +10 % to +30 % and 1.3 - 5 m/s by 2 s, growing. Bounds: gyration 4 %, speed 0.6 m/s.
    EXPECT_NEAR(end.gyration / start.gyration, 1.0, 0.04);
    EXPECT_LT(lateSpeed, 0.6);
}

} // namespace

// [SB12] Fig. 4: Ghost SPH keeps a zero-gravity body together. With the default air weights
// ("complete", GhostAir.cc: the air weighs what the liquid next to it lacks) measured -0.39 %
// and 0.056 m/s (float), +0.97 % and 0.070 m/s (double). The former default, "matched" (by
// the air's own packing), let the kept air's mass grow and the cube spread: +5.8 % and a late
// 3.7 m/s (seed 1, bench/history/diary-2026-11.md "Air that completes the liquid's density").
TEST(ZeroGravityCube, DefaultGhostAirKeepsTheCubeTogetherForTwoSeconds)
{
    ASSERT_EQ(GhostSettings().airWeights, AirWeights::Complete);
    expectCubeKeepsTogether(GhostSettings().airWeights);
}
