/// @file   test_pressure_model.cc
/// @brief  A pressure model written outside libghost, through its public interface alone
///         (PressureSolver.h, LiquidStep.h): "no pressure at all", under which a ball of
///         liquid must fall exactly as free particles do.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/ghost/LiquidStep.h>
#include <ghostfx/ghost/PressureSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.01);

/// Gravity alone: v* = v + dt g for the liquid, then Algorithm 3's remaining lines.
class NoPressure final : public PressureSolver
{
public:
    std::string name() const override { return "none"; }
    void step(LiquidStep& step, Real dt) override
    {
        ++steps;
        step.searchAndDensity();
        ParticleSet& set = step.particles();
        const Vec3 g = step.settings().gravity;
        auto& vstar = set.vectorChannel(LiquidStep::VELOCITY_STAR);
        for (std::size_t i = 0; i < set.size(); ++i) {
            const bool liquid = set.kinds()[i] == ParticleKind::Liquid;
            vstar[i] = liquid ? set.velocities()[i] + dt * g : set.velocities()[i];
        }
        step.setMaxAcceleration(g.length());
        step.finish(dt);
    }
    int steps = 0;
};

} // namespace

// Without pressure every liquid particle has the same velocity at every step, so XSPH (a sum
// of velocity differences) adds exactly nothing and the ball falls as one body: each particle's
// displacement after N steps of dt is the semi-implicit Euler sum dt^2 g N (N + 1) / 2. The
// tolerance, 1e-5 m, is single-precision rounding of positions near 0.1 m (6e-9 m) summed over
// the 100 steps with a wide margin; a model that let any force through (a pressure, the wall
// drag) would move particles apart by millimetres.
TEST(PressureModel, AToyModelWithoutPressureFallsFreely)
{
    GhostSettings settings;
    settings.spacing = H;
    settings.seed = 3;
    auto model = std::make_unique<NoPressure>();
    NoPressure* toy = model.get();
    GhostSolver solver(settings, std::move(model));
    EXPECT_EQ(solver.pressureSolver().name(), "none");
    solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0, 0.5, 0), Real(0.06), H / 2), "ball"));
    ASSERT_TRUE(solver.prepare());

    std::map<ParticleId, Vec3> start;
    const ParticleSet& p = solver.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid) start[p.ids()[i]] = p.positions()[i];
    }
    ASSERT_GT(start.size(), 500u);

    const Real dt = Real(1e-3);
    const int N = 100;
    for (int s = 0; s < N; ++s) solver.step(dt);
    EXPECT_EQ(toy->steps, N);

    const Vec3 expected = settings.gravity * (dt * dt * Real(N * (N + 1) / 2));
    double worst = 0;
    std::size_t liquid = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        ++liquid;
        const Vec3 moved = p.positions()[i] - start.at(p.ids()[i]);
        worst = std::max(worst, double((moved - expected).length()));
    }
    EXPECT_EQ(liquid, start.size());
    EXPECT_LT(worst, 1e-5) << "the ball should fall by " << expected << " m";
    // The density pass ran every step: the ball keeps the density its mass was scaled to
    // ([SB12] Sec. 4.6, mean rho0 with the air in place), within the 2 % a Poisson sampling
    // leaves after the initial relaxation.
    double meanError = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid)
            meanError += std::abs(double(p.densities()[i] / settings.restDensity) - 1);
    }
    EXPECT_LT(meanError / double(liquid), 0.02);
}
