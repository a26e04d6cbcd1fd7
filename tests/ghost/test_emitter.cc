/// @file   test_emitter.cc
/// @brief  Continuous emission ([SB12] Sec. 4.5.2) and the kill box: volume emitted per second,
///         no overlap between new and old liquid, particles leaving the domain removed.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/KeyedMotion.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/PoissonSampler.h>

#include "common/Tap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {
constexpr Real H = Real(0.01);
}

TEST(Emitter, EmitsCrossSectionTimesSpeedWithoutOverlap)
{
    // A 6 h x 6 h nozzle, 3 h tall, pouring straight down at 1 m/s without gravity (so the
    // speed stays 1 m/s): the volume rate is the cross-section times the speed, 3.6e-3 m^3/s.
    GhostSettings s;
    s.spacing = H;
    s.gravity = Vec3(0);
    s.seed = 2;
    s.killBox = Aabb{Vec3(-0.2f, -0.12f, -0.2f), Vec3(0.2f, 0.2f, 0.2f)};
    GhostSolver solver(s);
    const Real half = 3 * H;
    solver.addEmitter(
        makeLevelSet(makeBoxLevelSet(Vec3(-half, 0, -half), Vec3(half, 3 * H, half), H / 2),
                     "nozzle"),
        Vec3(0, -1, 0));
    const Real dt = Real(1) / 1200;
    solver.step(dt);
    const std::size_t initial = solver.count(ParticleKind::Liquid);
    const int steps = 120; // 0.1 s: the stream front reaches y = -0.1 m, inside the kill box
    // New liquid must join the old without overlap: after every step, the particles emitted in
    // that step (ids from the id counter before it) are measured against all other liquid.
    double minSpacing = 1e9;
    for (int k = 0; k < steps; ++k) {
        const ParticleId firstNew = solver.particles().nextId();
        solver.step(dt);
        const ParticleSet& p = solver.particles();
        std::vector<Vec3> liquid;
        std::vector<std::uint8_t> isNew;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            liquid.push_back(p.positions()[i]);
            isNew.push_back(p.ids()[i] >= firstNew);
        }
        NeighborGrid grid(H);
        grid.build(liquid);
        for (std::size_t i = 0; i < liquid.size(); ++i) {
            if (!isNew[i]) continue;
            grid.forEachNeighbor(Index(i), [&](Index j, const Vec3&, Real r) {
                if (j != i) minSpacing = std::min(minSpacing, double(r));
            });
        }
    }
    const double emitted = double(solver.count(ParticleKind::Liquid) - initial);
    const double volume = emitted * double(solver.particleMass()) / double(s.restDensity);
    const double expected = double(2 * half) * double(2 * half) * 1.0 * steps * double(dt);
    const double r = double(PoissonSettings::SB12_RADIUS_FACTOR * H);
    std::printf("[measured] emitter: %g particles in %.3f s = %.3e m^3, expected %.3e m^3 "
                "(%.1f %%); closest liquid pair %.3f r; killed %zu\n",
                emitted, steps * double(dt), volume, expected, 100 * (volume - expected) / expected,
                minSpacing / r, solver.killedCount());
    // Volume per particle m / rho0 holds for liquid at rest density; the sampler fills the
    // nozzle at its usual packing, and the stream sheds the nozzle's boundary layer. Measured
    // +4 % to +12 % as the air treatment changed, -1.7 % since the liquid inside the emitter
    // is held at its velocity, -3.2 to -3.5 % since the fills are paid by its credit; bound 8 %.
    EXPECT_NEAR(volume / expected, 1.0, 0.08);
    // New particles are placed at least r from every particle, then all move one step (new
    // ones at the emitter speed, old ones slowed a little by the stream's pressure): bound
    // 0.8 r. (Further down the stream, pairs compress to about 0.25 r at this soft stiffness:
    // Mach 0.27 at k = 2000 Pa; that is the flow, not the emission.)
    EXPECT_GT(minSpacing, 0.8 * r);
    EXPECT_EQ(solver.emittedCount(), initial + std::size_t(emitted) + solver.killedCount());
}

TEST(Emitter, TapUnderGravityPoursItsRateAtAnyStep)
{
    // The tomato's tap without the tomato at 5 mm spacing, Tait pressure ([SB12]'s step): an
    // 8 x 8 x 3 cm nozzle pouring 1 m/s downwards under gravity, CFL steps at 0.4 and 0.2.
    // Measured from 0.05 s (the nozzle's first fill has left it) to 0.12 s: the mass that
    // leaves through the nozzle's bottom per second, against rho0 v A = 6.4 kg/s, and the
    // liquid inside the nozzle against rho0 V / m at rest density.
    // Before the fills were paid by the emitter's credit they packed the nozzle 5-9 % over rest
    // density and it poured 7.4-7.5 kg/s (+16 %) at both steps; now 6.5 / 6.4 kg/s with the
    // nozzle 90-93 % full (its top layer is the gap the next fill closes), bench/RESULTS.md,
    // "An emitter that pours its rate". Bounds: the rate within 5 %, the two steps within 4 %
    // of each other, the nozzle at least 85 % full.
    const Real h = H / 2;
    const double from = 0.05, to = 0.12, rate = 1000 * 0.08 * 0.08 * 1.0;
    auto inNozzle = [](const Vec3& x) {
        return std::abs(x[0]) < 0.04f && std::abs(x[2]) < 0.04f && x[1] > 0.47f && x[1] < 0.5f;
    };
    auto pour = [&](Real cfl, double& fullness) {
        GhostSettings s;
        s.spacing = h;
        s.substeps = 0;
        s.cflNumber = cfl;
        s.seed = 1;
        GhostSolver solver(s);
        ghostfx::testing::addTap(solver, h);
        auto below = [&] {
            std::size_t n = 0;
            const ParticleSet& p = solver.particles();
            for (std::size_t i = 0; i < p.size(); ++i) {
                n += p.kinds()[i] == ParticleKind::Liquid && p.positions()[i][1] < 0.47f;
            }
            return double(n);
        };
        ghostfx::testing::runFor(solver, from, [] {});
        const double belowFrom = below();
        double inside = 0;
        int steps = 0;
        ghostfx::testing::runFor(solver, to, [&] {
            const ParticleSet& p = solver.particles();
            for (std::size_t i = 0; i < p.size(); ++i) {
                inside += p.kinds()[i] == ParticleKind::Liquid && inNozzle(p.positions()[i]);
            }
            ++steps;
        });
        const double m = double(solver.particleMass());
        const double poured = (below() - belowFrom) * m / (solver.time() - from);
        fullness = inside / steps / (1000 * 0.08 * 0.08 * 0.03 / m);
        std::printf("[measured] Tait tap at CFL %.1f: %.3f kg/s out of the nozzle from %.2f to "
                    "%.3f s against %.1f kg/s (%+.1f %%), nozzle %.1f %% full\n",
                    double(cfl), poured, from, double(solver.time()), rate,
                    100 * (poured / rate - 1), 100 * fullness);
        return poured / rate;
    };
    double fullDefault = 0, fullSmaller = 0;
    const double atDefault = pour(Real(0.4), fullDefault);
    const double atSmaller = pour(Real(0.2), fullSmaller);
    EXPECT_NEAR(atDefault, 1.0, 0.05);
    EXPECT_NEAR(atSmaller, 1.0, 0.05);
    EXPECT_NEAR(atSmaller / atDefault, 1.0, 0.04);
    EXPECT_GT(fullDefault, 0.85);
    EXPECT_GT(fullSmaller, 0.85);
}

namespace {

/// What a moving emitter poured over a run: its mass rate against rho0 |v| A, and how far the
/// particles it emitted each step moved from the velocity it gives them.
struct MovingPour
{
    double rateRatio = 0;     ///< emitted mass per second / (rho0 |v| A)
    double crossSection = 0;  ///< m^2, the solver's
    double velocityError = 0; ///< largest |mean new velocity - expected| over the steps (m/s)
    double velocityRms = 0;   ///< rms of |v_i - expected_i| over all new particles (m/s)
};

/// A 6 h x 6 h nozzle, 3 h tall, pouring along -y of its own frame at 1 m/s without gravity,
/// placed by `motion`; `expected(x, t)` is the world velocity the emitter should give liquid
/// at x at time t. Measures 120 steps of 1/1200 s after the first fill.
template <typename Expected>
MovingPour pourMoving(const LevelSet& nozzle, RigidMotion motion, Expected&& expected)
{
    GhostSettings s;
    s.spacing = H;
    s.gravity = Vec3(0);
    s.seed = 2;
    s.killBox = Aabb{Vec3(-0.4f, -0.4f, -0.4f), Vec3(0.4f, 0.4f, 0.4f)};
    GhostSolver solver(s);
    solver.addMovingEmitter(nozzle, Vec3(0, -1, 0), std::move(motion));
    const Real dt = Real(1) / 1200;
    solver.step(dt);
    const std::size_t initial = solver.emittedCount();
    const int steps = 120;
    MovingPour out;
    double sumSq = 0;
    std::size_t counted = 0;
    for (int k = 0; k < steps; ++k) {
        const ParticleId firstNew = solver.particles().nextId();
        const double emittedAt = solver.time();
        solver.step(dt);
        // New particles took the emitter's velocity at the start of the step, then moved one
        // step: compared with the velocity expected where they started.
        const ParticleSet& p = solver.particles();
        Vec3d sum(0.0);
        std::size_t n = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid || p.ids()[i] < firstNew) continue;
            const Vec3 start = p.positions()[i] - dt * p.velocities()[i];
            const Vec3d d = Vec3d(p.velocities()[i]) - Vec3d(expected(start, emittedAt));
            sum += d;
            sumSq += d.lengthSqr();
            ++n;
        }
        counted += n;
        if (n > 0) out.velocityError = std::max(out.velocityError, (sum / double(n)).length());
    }
    const double m = double(solver.particleMass());
    const double poured = double(solver.emittedCount() - initial) * m / (steps * double(dt));
    out.crossSection = solver.emitterRates()[0].crossSection;
    out.rateRatio = poured / solver.emitterRates()[0].massRate;
    out.velocityRms = std::sqrt(sumSq / double(std::max<std::size_t>(counted, 1)));
    std::printf("[measured] moving emitter: %.3f kg/s against rho0 |v| A = %.3f kg/s (%+.1f %%), "
                "A = %.3e m^2; new liquid's mean velocity off by at most %.4f m/s, rms %.4f m/s\n",
                poured, solver.emitterRates()[0].massRate, 100 * (out.rateRatio - 1),
                out.crossSection, out.velocityError, out.velocityRms);
    return out;
}

} // namespace

TEST(Emitter, TranslatingEmitterPoursItsRateAndAddsItsVelocity)
{
    // A hose sweeping sideways at 0.5 m/s while pouring 1 m/s down in its own frame: the
    // liquid leaves at (0.5, -1, 0) m/s in the world, and the rate is rho0 |v| A in the
    // emitter's frame, whatever its motion.
    const Real half = 3 * H;
    const LevelSet nozzle = makeLevelSet(
        makeBoxLevelSet(Vec3(-half, 0, -half), Vec3(half, 3 * H, half), H / 2), "hose");
    KeyedMotion keys;
    keys.keys = {RigidKey{0, Vec3d(0.0), Vec3d(0.0)}, RigidKey{1, Vec3d(0.5, 0, 0), Vec3d(0.0)}};
    const MovingPour pour = pourMoving(nozzle, keys.motion(), [](const Vec3&, double) {
        return Vec3(0.5f, -1, 0);
    });
    // The cross-section is the 6 h x 6 h outline, measured on a grid of half the voxel
    // (LevelSet::shadowArea): 3 % covers a cell's width of outline.
    EXPECT_NEAR(pour.crossSection, 36e-4, 0.03 * 36e-4);
    // The target: within 5 % of rho0 |v| A.
    EXPECT_NEAR(pour.rateRatio, 1.0, 0.05);
    // One step of pressure between neighbours at the nozzle's packing changes a new
    // particle's velocity by a few cm/s: measured rms 3.7 cm/s over all new particles, the
    // mean of one step's fills at most 8 cm/s off. Bounds 6 cm/s and 15 cm/s; a jet without
    // the sweep would be 0.5 m/s off.
    EXPECT_LT(pour.velocityRms, 0.06);
    EXPECT_LT(pour.velocityError, 0.15);
}

TEST(Emitter, RotatingEmitterTurnsItsJetAndAddsItsSpin)
{
    // A sprinkler arm: a nozzle 20 cm below the z axis, turning about it at 180 degrees/s
    // (pi rad/s) and pouring 1 m/s away from the axis in its own frame. In the world the
    // liquid leaves at R(t) (0, -1, 0) plus omega x r: 0.63 m/s of spin at the nozzle.
    const Real half = 3 * H;
    const LevelSet nozzle = makeLevelSet(
        makeBoxLevelSet(Vec3(-half, -0.2f - 3 * H, -half), Vec3(half, -0.2f, half), H / 2),
        "arm");
    KeyedMotion keys;
    keys.keys = {RigidKey{0, Vec3d(0.0), Vec3d(0.0)}, RigidKey{1, Vec3d(0.0), Vec3d(0, 0, 180)}};
    const double omega = M_PI;
    const MovingPour pour = pourMoving(nozzle, keys.motion(), [&](const Vec3& x, double t) {
        const double angle = omega * t;
        const Vec3d jet(std::sin(angle), -std::cos(angle), 0);
        const Vec3d spin = Vec3d(0, 0, omega).cross(Vec3d(x));
        return Vec3(jet + spin);
    });
    // Tolerances as for the translating emitter (its comments; measured rms 3.4 cm/s, the
    // worst step's mean 7 cm/s). A jet without the spin would be 0.6 m/s off, one not turned
    // with the arm up to 0.3 m/s.
    EXPECT_NEAR(pour.crossSection, 36e-4, 0.03 * 36e-4);
    EXPECT_NEAR(pour.rateRatio, 1.0, 0.05);
    EXPECT_LT(pour.velocityRms, 0.06);
    EXPECT_LT(pour.velocityError, 0.15);
}

TEST(Emitter, KillBoxRemovesLiquidLeavingTheDomain)
{
    GhostSettings s;
    s.spacing = H;
    s.killBox = Aabb{Vec3(-0.1f, -0.05f, -0.1f), Vec3(0.1f, 0.1f, 0.1f)};
    GhostSolver solver(s);
    solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.03), H / 2), "drop"));
    solver.step(Real(1) / 1200);
    const std::size_t start = solver.count(ParticleKind::Liquid);
    // The drop falls 0.05 m (its centre passes the floor of the box) after 0.1 s.
    for (int k = 0; k < 180; ++k) solver.step(Real(1) / 1200);
    EXPECT_GT(solver.killedCount(), start / 2);
    EXPECT_EQ(solver.count(ParticleKind::Liquid) + solver.killedCount(), start);
    for (std::size_t i = 0; i < solver.particles().size(); ++i) {
        if (solver.particles().kinds()[i] == ParticleKind::Liquid) {
            ASSERT_TRUE(s.killBox.contains(solver.particles().positions()[i]));
        }
    }
}

TEST(Emitter, LaterEmitterInAnEmptySceneWaitsForItsStart)
{
    // No liquid until the tap opens at t = 0.05 s: the solver steps time (and the solids)
    // until then, then emits, scales the mass and runs as usual.
    GhostSettings s;
    s.spacing = H;
    s.seed = 4;
    GhostSolver solver(s);
    const Real half = 3 * H;
    const LevelSet nozzle =
        makeLevelSet(makeBoxLevelSet(Vec3(-half, 0, -half), Vec3(half, 3 * H, half), H / 2), "tap");
    solver.addEmitter(nozzle, Vec3(0, -1, 0), 0.05);
    const Real dt = Real(1) / 1200;
    std::size_t stepsWithoutLiquid = 0;
    while (solver.time() < 0.1) {
        solver.step(dt);
        if (solver.count(ParticleKind::Liquid) == 0) ++stepsWithoutLiquid;
    }
    std::printf("[measured] late emitter: %zu steps without liquid (0.05 s at dt 1/1200 s = 60), "
                "%zu liquid at t = 0.1 s, particle mass %.3e kg\n",
                stepsWithoutLiquid, solver.count(ParticleKind::Liquid),
                double(solver.particleMass()));
    // Exactly the steps before t = 0.05 s (one more for the round-off of summed steps).
    EXPECT_GE(stepsWithoutLiquid, 59u);
    EXPECT_LE(stepsWithoutLiquid, 61u);
    EXPECT_GT(solver.count(ParticleKind::Liquid), 0u);
    EXPECT_GT(solver.particleMass(), Real(0));

    // Nothing that could ever bring liquid (no body, no emitter): refused at the first step.
    GhostSolver ended(s);
    ended.addSolid(nozzle);
    try {
        ended.step(dt);
        FAIL() << "a scene with no liquid and no emitter to come must be refused";
    } catch (const ValueError& e) {
        EXPECT_NE(std::string(e.what()).find("no liquid particles"), std::string::npos) << e.what();
    }
}

TEST(SolidCollision, ParticleThatTunnelsPastTheBandGoesBackAndNoneStaysInside)
{
    // A drop at 40 m/s towards a 0.5 m thick block, with one step of 10 ms: the drop ends 0.3 m
    // inside the floor, ten times deeper than the floor's level-set band, where the closest
    // point is unknown. Every particle goes back to where the step started it.
    GhostSettings s;
    s.spacing = H;
    s.seed = 5;
    GhostSolver solver(s);
    const LevelSet floor = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.1f, -0.5f, -0.1f), Vec3(0.1f, 0, 0.1f), H / 2), "block");
    solver.addSolid(floor);
    solver.addLiquid(
        makeLevelSet(makeBoxLevelSet(Vec3(-0.03f, 0.1f, -0.03f), Vec3(0.03f, 0.16f, 0.03f), H / 2),
                     "drop"),
        Vec3(0, -40, 0));
    solver.step(Real(0.01));
    const ParticleSet& p = solver.particles();
    double deepest = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid)
            deepest = std::min(deepest, double(floor.phi(p.positions()[i])));
    }
    std::printf(
        "[measured] tunnelling drop: %llu of %zu particles put back, deepest liquid %.2e m\n",
        (unsigned long long)solver.restoredFromSolidsCount(), solver.count(ParticleKind::Liquid),
        deepest);
    EXPECT_GT(solver.restoredFromSolidsCount(), 0u);
    EXPECT_GE(deepest, -1e-3 * double(H));
}
