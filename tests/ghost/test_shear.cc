/// @file   test_shear.cc
/// @brief  [SB12] Sec. 4.7, Fig. 9: constant shear flow v = (0, x, 0). The exact acceleration
///         is zero, so each particle's measured acceleration (second difference of its
///         position) is SPH error E (Eq. 4); its change between steps, Delta E (Eq. 5), jumps
///         when the air is resampled. The jump must be of the size of E, not larger.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <unordered_map>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

TEST(ShearFlow, AirResamplingJumpIsOfTheSizeOfTheSphError)
{
    const Real H = Real(0.01);
    GhostSettings s;
    s.spacing = H;
    s.gravity = Vec3(0);
    s.seed = 8;
    s.airResampleSteps = 10;
    GhostSolver solver(s);
    solver.addLiquid(makeLevelSet(makeBoxLevelSet(Vec3(-0.06f), Vec3(0.06f), H / 2), "cube"));
    auto& v = solver.particles().velocities();
    for (std::size_t i = 0; i < v.size(); ++i)
        v[i] = Vec3(0, solver.particles().positions()[i][0], 0);

    const Real dt = Real(1) / 1200;
    const int steps = 33;
    // Positions of every liquid particle by id, per step.
    std::vector<std::unordered_map<ParticleId, Vec3d>> history;
    auto record = [&] {
        std::unordered_map<ParticleId, Vec3d> x;
        const ParticleSet& p = solver.particles();
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] == ParticleKind::Liquid) x[p.ids()[i]] = Vec3d(p.positions()[i]);
        }
        history.push_back(std::move(x));
    };
    record();
    for (int n = 0; n < steps; ++n) {
        solver.step(dt);
        record();
    }
    // A_i(t^n) = (x^{n+1} - 2 x^n + x^{n-1}) / dt^2 for n = 1 .. steps - 1.
    const double dt2 = double(dt) * double(dt);
    std::vector<std::unordered_map<ParticleId, Vec3d>> accel(history.size());
    for (std::size_t n = 1; n + 1 < history.size(); ++n) {
        for (const auto& [id, x] : history[n]) {
            accel[n][id] = (history[n + 1].at(id) - 2.0 * x + history[n - 1].at(id)) / dt2;
        }
    }
    // Steps 3 .. 32 as in Fig. 9. Step n's position update comes from solver step n - 1, whose
    // air was resampled when (n - 1) % 10 == 0: the jump shows in Delta E at those n.
    double meanE = 0, countE = 0, maxE = 0, maxJumpResample = 0, meanJumpResample = 0,
           nResample = 0;
    double meanJumpOther = 0, nOther = 0;
    for (std::size_t n = 3; n + 1 < history.size(); ++n) {
        double sumE = 0, sumDE = 0, maxDE = 0, count = 0;
        for (const auto& [id, a] : accel[n]) {
            const double E = a.length();
            const double dE = (a - accel[n - 1].at(id)).length();
            sumE += E;
            sumDE += dE;
            maxDE = std::max(maxDE, dE);
            count += 1;
            maxE = std::max(maxE, E);
        }
        const bool resampled = (n - 1) % std::size_t(s.airResampleSteps) == 0;
        if (resampled) {
            meanJumpResample += sumDE / count;
            maxJumpResample = std::max(maxJumpResample, maxDE);
            nResample += 1;
        } else {
            meanE += sumE / count;
            countE += 1;
            meanJumpOther += sumDE / count;
            nOther += 1;
        }
    }
    meanE /= countE;
    meanJumpResample /= nResample;
    meanJumpOther /= nOther;
    std::printf("[measured] shear: mean E %.4f m/s^2 (max %.4f), mean Delta E at resampling %.4f "
                "(max %.4f), elsewhere %.4f; ratio jump / E = %.3f\n",
                meanE, maxE, meanJumpResample, maxJumpResample, meanJumpOther,
                meanJumpResample / meanE);
    ASSERT_GT(nResample, 1);
    // [SB12] Fig. 9: the resampling jump is "of the same magnitude as the SPH acceleration
    // error E". Bound: mean Delta E at resampling steps at most 2 x mean E, and the largest
    // jump at most 2 x the largest E. Measured: 0.23 x mean E, 0.22 x max E. Our air fades in
    // and out over the resampling interval (GhostSolver::resampleAir), so resampling steps
    // barely differ from the others (measured mean Delta E 3.60 vs 3.37 m/s^2): bound 1.5 x.
    EXPECT_LT(meanJumpResample, 2.0 * meanE);
    EXPECT_LT(maxJumpResample, 2.0 * maxE);
    EXPECT_LT(meanJumpResample, 1.5 * meanJumpOther);
}
