/// @file   test_whitewater.cc
/// @brief  Whitewater from the liquid (Whitewater.h, after Ihmsen et al. 2012): none from a
///         still tank or a drop in free fall, spray and foam where a drop hits a floor,
///         removal in solids and outside the kill box, and the same particles whatever the
///         liquid's order and the thread count.
#include "common/Shapes.h"

#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/ghost/Whitewater.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.02);

GhostSettings liquidSettings(Real spacing = H)
{
    GhostSettings s;
    s.spacing = spacing;
    s.pressure = PressureModel::Dfsph;
    s.substeps = 0;
    s.seed = 4;
    return s;
}

LevelSet box(const Vec3& lo, const Vec3& hi, const char* name)
{
    return makeLevelSet(makeBoxLevelSet(lo, hi, H / 2), name);
}

LiquidSnapshot snapshot(const GhostSolver& solver)
{
    const GhostSettings& s = solver.settings();
    return LiquidSnapshot::fromParticles(solver.particles(), s.spacing, s.supportFactor, s.gravity);
}

/// What a drop's whitewater did over its frames.
struct DropWhitewater
{
    std::size_t before = 0;  ///< the most particles before the drop touched the floor
    double particleSeconds = 0; ///< the particle count summed over the frames, times the frame
};

/// A 20 cm drop falling from `height` (its bottom) onto a floor at spacing `h`, with whitewater
/// each frame; returns the whitewater and, through `stats`, what it did.
Whitewater dropOnFloor(double height, int frames, DropWhitewater& stats, Real h = H)
{
    GhostSolver solver(liquidSettings(h));
    solver.addSolid(makeLevelSet(makeBoxLevelSet(Vec3(-0.6f, -0.1f, -0.6f), Vec3(0.6f, 0, 0.6f),
                                                 h / 2),
                                 "floor"));
    solver.addLiquid(makeLevelSet(
        makeSphereLevelSet(Vec3(0, Real(height + 0.1), 0), Real(0.1), h / 2), "drop"));
    Whitewater white{WhitewaterSettings()};
    white.setSolids([](const Vec3& x) { return x[1]; });
    const double hit = std::sqrt(2 * height / 9.81);
    const double dt = 1.0 / double(solver.settings().frameRate);
    for (int f = 0; f < frames; ++f) {
        solver.advanceFrame();
        white.step(snapshot(solver), Real(dt));
        if (solver.time() < hit - 0.02) stats.before = std::max(stats.before, white.size());
        stats.particleSeconds += double(white.size()) * dt;
    }
    return white;
}

} // namespace

// A still tank (40 x 20 x 40 cm of water, 2 s) makes no whitewater: its particles move at
// millimetres per second, far below the energy potential's 0.45 m/s (0.1 J/kg).
TEST(Whitewater, AStillTankMakesNone)
{
    GhostSolver solver(liquidSettings());
    solver.addSolid(makeLevelSet(ghostfx::testing::closedTankGrid(Vec3(-0.2f, 0, -0.2f),
                                                                   Vec3(0.2f, 0.4f, 0.2f), 0.08,
                                                                   H / 2),
                                 "tank"));
    solver.addLiquid(box(Vec3(-0.2f, 0, -0.2f), Vec3(0.2f, 0.2f, 0.2f), "water"));
    Whitewater white{WhitewaterSettings()};
    std::size_t most = 0;
    for (int f = 0; f < 60; ++f) {
        solver.advanceFrame();
        white.step(snapshot(solver), Real(1.0 / 30));
        most = std::max(most, white.size());
    }
    std::printf("[measured] still tank, 2 s: %zu whitewater particles made\n", std::size_t(white.made()));
    EXPECT_EQ(white.made(), 0u);
    EXPECT_EQ(most, 0u);
}

// A drop in free fall makes none until it hits the floor: it moves as a whole, and whitewater
// reads only velocity differences. Falling 0.5 m it hits at 3.1 m/s; the splash makes spray
// (above the liquid) and foam (at its surface) within 0.3 s of the impact.
TEST(Whitewater, ADropMakesNoneInFreeFallAndSprayWhereItHits)
{
    DropWhitewater stats;
    const Whitewater white = dropOnFloor(0.5, 18, stats);
    const std::size_t before = stats.before;
    std::printf("[measured] drop: %zu whitewater before the impact, %llu made, %zu now (%zu spray, "
                "%zu foam, %zu bubbles)\n",
                before, (unsigned long long)white.made(), white.size(),
                white.count(WhitewaterType::Spray), white.count(WhitewaterType::Foam),
                white.count(WhitewaterType::Bubble));
    EXPECT_EQ(before, 0u);
    EXPECT_GT(white.made(), 50u);
    EXPECT_GT(white.count(WhitewaterType::Spray), 0u);
    // Nothing inside the floor (y < 0).
    for (const Vec3& x : white.positions()) EXPECT_GE(x[1], Real(0));
}

// The amount of whitewater depends little on the spacing: its rates are per volume of liquid and
// second, not per particle ([IAGT12] counts per particle, which would make 2.9 times as many at
// 1.4 cm as at 2 cm). A drop splashing on a floor at 2 and 1.4 cm: measured 15 % fewer made at
// 1.4 cm, and 42 % fewer particle-seconds (the count summed over the frames). The bounds, a
// quarter and a half, leave room for the trapped-air potential, which reads velocity differences
// across the kernel support and so sees less of them as the support shrinks with the spacing.
TEST(Whitewater, TheAmountHardlyDependsOnTheSpacing)
{
    DropWhitewater coarse, fine;
    const Whitewater a = dropOnFloor(0.5, 18, coarse, H);
    const Whitewater b = dropOnFloor(0.5, 18, fine, Real(0.014));
    std::printf("[measured] spacing: made %llu at 2 cm, %llu at 1.4 cm; particle-seconds %.1f, "
                "%.1f\n",
                (unsigned long long)a.made(), (unsigned long long)b.made(), coarse.particleSeconds,
                fine.particleSeconds);
    EXPECT_NEAR(double(b.made()) / double(a.made()), 1.0, 0.25);
    EXPECT_NEAR(fine.particleSeconds / coarse.particleSeconds, 1.0, 0.5);
}

// The same liquid in another order, and at 1 and 2 threads, gives the same whitewater bit for
// bit (the liquid is sorted by id; each particle's random numbers are seeded by its id); so does
// a whitewater continued from its saved state halfway.
TEST(Whitewater, TheLiquidsOrderAndTheThreadCountChangeNothing)
{
    GhostSolver solver(liquidSettings());
    solver.addSolid(box(Vec3(-0.6f, -0.1f, -0.6f), Vec3(0.6f, 0, 0.6f), "floor"));
    solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0, 0.2f, 0), 0.1f, H / 2), "drop"));
    solver.particles().velocities().assign(solver.particles().size(), Vec3(0, -3, 0));
    std::vector<LiquidSnapshot> frames;
    for (int f = 0; f < 8; ++f) {
        solver.advanceFrame();
        frames.push_back(snapshot(solver));
    }
    auto run = [&](bool shuffled, int threads, std::size_t resumeAt = 0) {
        parallel::ThreadLimit limit(threads);
        Whitewater white{WhitewaterSettings()};
        for (std::size_t f = 0; f < frames.size(); ++f) {
            LiquidSnapshot liquid = frames[f];
            if (f == resumeAt && f > 0) {
                Whitewater resumed{WhitewaterSettings()};
                resumed.restoreState(white.saveState());
                white = resumed;
            }
            if (shuffled) {
                std::vector<std::size_t> order(liquid.ids.size());
                for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
                std::shuffle(order.begin(), order.end(), std::mt19937(7));
                LiquidSnapshot s = liquid;
                for (std::size_t k = 0; k < order.size(); ++k) {
                    s.positions[k] = liquid.positions[order[k]];
                    s.velocities[k] = liquid.velocities[order[k]];
                    s.ids[k] = liquid.ids[order[k]];
                }
                liquid = s;
            }
            white.step(liquid, Real(1.0 / 30));
        }
        return white;
    };
    const Whitewater a = run(false, 2), b = run(true, 2), c = run(false, 1), d = run(false, 2, 4);
    std::printf("[measured] determinism: %zu whitewater particles\n", a.size());
    ASSERT_GT(a.size(), 0u);
    for (const Whitewater* other : {&b, &c, &d}) {
        ASSERT_EQ(other->size(), a.size());
        EXPECT_TRUE(std::equal(a.positions().begin(), a.positions().end(),
                               other->positions().begin()));
        EXPECT_TRUE(std::equal(a.ids().begin(), a.ids().end(), other->ids().begin()));
        EXPECT_TRUE(std::equal(a.types().begin(), a.types().end(), other->types().begin()));
        EXPECT_TRUE(std::equal(a.ages().begin(), a.ages().end(), other->ages().begin()));
        EXPECT_TRUE(std::equal(a.velocities().begin(), a.velocities().end(),
                               other->velocities().begin()));
    }
}

// Particles leaving the kill box, and particles inside a solid, are removed; bad settings are
// refused in one line.
TEST(Whitewater, ParticlesInSolidsOrOutsideTheKillBoxAreRemoved)
{
    DropWhitewater stats;
    Whitewater white = dropOnFloor(0.5, 14, stats);
    ASSERT_GT(white.size(), 0u);
    LiquidSnapshot nothing;
    // A solid filling everything below y = 1 m: every particle is inside it.
    white.setSolids([](const Vec3& x) { return x[1] - Real(1); });
    white.step(nothing, Real(0));
    EXPECT_EQ(white.size(), 0u);
    Whitewater boxed = dropOnFloor(0.5, 14, stats);
    boxed.setKillBox(Aabb{Vec3(-0.05f, -1, -0.05f), Vec3(0.05f, 1, 0.05f)});
    boxed.step(nothing, Real(0));
    for (const Vec3& x : boxed.positions()) {
        EXPECT_LE(std::abs(x[0]), Real(0.05));
        EXPECT_LE(std::abs(x[2]), Real(0.05));
    }
    WhitewaterSettings bad;
    bad.energyMax = Real(0.05);
    try {
        Whitewater refused(bad);
        ADD_FAILURE() << "energy max below min was taken";
    } catch (const ghostfx::ValueError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "whitewater setting energyMax = 0.05: expected a number above energyMin (0.5)");
    }
}

namespace {

/// The distance (m) from x to the nearest liquid particle of `liquid`, and the mean vertical
/// velocity (m/s) of the liquid within two spacings of x.
double nearestLiquid(const LiquidSnapshot& liquid, const Vec3& x, double* vy = nullptr)
{
    double best = 1e9, sum = 0;
    int n = 0;
    for (std::size_t i = 0; i < liquid.positions.size(); ++i) {
        const double d = double((liquid.positions[i] - x).length());
        best = std::min(best, d);
        if (d > 2 * double(H)) continue;
        sum += double(liquid.velocities[i][1]);
        ++n;
    }
    if (vy) *vy = n ? sum / n : 0.0;
    return best;
}

} // namespace

// A dam break (a 20 x 30 x 20 cm column in a 80 x 50 x 20 cm tank, 2 cm spacing, 3 s): spray
// is made where the surge hits the far wall, the whitewater count rises and then falls as
// foam dissolves (lifetimes 1-3 s) once the splash settles; at least 95 % of the foam sits
// within two spacings of the liquid (the bound; measured 100 %: foam is whitewater
// where the liquid fraction is 0.2-0.7), and bubbles rise through the liquid (mean vertical
// velocity relative to the liquid within two spacings positive; measured 0.10 m/s against
// the 0.29 m/s of still liquid).
TEST(Whitewater, ADamBreakMakesSprayAtTheWallFoamOnTheSurfaceAndRisingBubbles)
{
    GhostSolver solver(liquidSettings());
    solver.addSolid(makeLevelSet(ghostfx::testing::closedTankGrid(Vec3(0, 0, 0),
                                                                   Vec3(0.8f, 0.5f, 0.2f), 0.08,
                                                                   H / 2),
                                 "tank"));
    solver.addLiquid(box(Vec3(0, 0, 0), Vec3(0.2f, 0.3f, 0.2f), "column"));
    Whitewater white{WhitewaterSettings()};
    white.setSolids([](const Vec3& x) {
        return Real(std::min({x[0], 0.8f - x[0], x[1], 0.5f - x[1], x[2], 0.2f - x[2]}));
    });
    std::size_t peak = 0, sprayPeak = 0, sprayEarly = 0;
    double sprayPeakTime = 0, sprayX = 0, foamNear = 0, foamAll = 0, rise = 0, bubbles = 0;
    for (int f = 0; f < 90; ++f) {
        solver.advanceFrame();
        const LiquidSnapshot liquid = snapshot(solver);
        white.step(liquid, Real(1.0 / 30));
        const std::size_t spray = white.count(WhitewaterType::Spray);
        if (solver.time() < 0.3) sprayEarly = std::max(sprayEarly, spray);
        if (spray > sprayPeak) {
            sprayPeak = spray;
            sprayPeakTime = solver.time();
            sprayX = 0;
            for (std::size_t k = 0; k < white.size(); ++k) {
                if (white.types()[k] == WhitewaterType::Spray)
                    sprayX += double(white.positions()[k][0]) / double(spray);
            }
        }
        peak = std::max(peak, white.size());
        for (std::size_t k = 0; k < white.size(); ++k) {
            if (white.types()[k] == WhitewaterType::Foam) {
                foamAll += 1;
                foamNear += nearestLiquid(liquid, white.positions()[k]) <= 2 * double(H);
            }
            if (white.types()[k] == WhitewaterType::Bubble) {
                double around = 0;
                nearestLiquid(liquid, white.positions()[k], &around);
                bubbles += 1;
                rise += double(white.velocities()[k][1]) - around;
            }
        }
    }
    std::printf("[measured] dam break: spray peaks at %zu particles at %.2f s, mean x %.2f m "
                "(%zu before 0.3 s); whitewater peak %zu particles, %zu at 3 s; foam within 2 h "
                "of the liquid %.1f %% (%.0f samples); bubbles rise at %.3f m/s relative to the "
                "liquid (%.0f samples)\n",
                sprayPeak, sprayPeakTime, sprayX, sprayEarly, peak, white.size(),
                100 * foamNear / std::max(1.0, foamAll), foamAll, rise / std::max(1.0, bubbles),
                bubbles);
    // The surge reaches the far wall (x = 0.8 m) at about 0.35 s and climbs it: the spray is
    // made there; the surge's front sprays a little on its way (under a tenth of it).
    EXPECT_GE(sprayPeakTime, 0.3);
    EXPECT_GT(sprayX, 0.55);
    EXPECT_LT(double(sprayEarly), 0.1 * double(sprayPeak));
    EXPECT_LT(double(white.size()), 0.9 * double(peak));
    EXPECT_GE(foamNear, 0.95 * foamAll);
    EXPECT_GT(foamAll, 0);
    EXPECT_GT(bubbles, 0);
    EXPECT_GT(rise, 0);
}
