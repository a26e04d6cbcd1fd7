/// @file   test_resume.cc
/// @brief  Solver state save / restore (in memory; the HDF5 round trip is in
///         tests/vdbio/test_checkpoint.cc), the restore contract, the step observer, and
///         "model only what the scene requires": which particle channels a solver creates.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include "common/ResumeScene.h"
#include "common/StateDiff.h"

#include "common/Expect.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.01);

/// The shared scene with this file's seed and the floor sliding at 5 cm/s.
struct Scene : ghostfx::testing::ResumeScene
{
    Scene(Method method, int substeps) : ResumeScene(method, substeps, Vec3(Real(0.05), 0, 0), 5) {}
};

using ghostfx::testing::firstDifference;
using ghostfx::testing::sameBytes;

} // namespace

TEST(Resume, GhostInMemoryContinuationIsBitIdentical)
{
    // 3 frames uninterrupted vs 1 frame, save, restore into a new solver, 2 frames. CFL-adaptive
    // steps, so a wrong max acceleration would change every later dt.
    const Scene scene(Method::Ghost, 0);
    const int frames = 3, split = 1;
    GhostSolver whole(scene.settings);
    scene.start(whole, frames);

    GhostSolver first(scene.settings);
    scene.start(first, split);
    const SolverState saved = first.saveState();

    GhostSolver resumed(scene.settings);
    resumed.restoreState(saved);
    scene.addInputs(resumed);
    // The floor's ghosts came with the state: re-adding the floor must not sample it again.
    EXPECT_EQ(resumed.count(ParticleKind::GhostSolid), first.count(ParticleKind::GhostSolid));
    EXPECT_EQ(resumed.particles().size(), first.particles().size());
    while (resumed.frame() < frames) resumed.advanceFrame();

    const std::string difference = firstDifference(whole.saveState(), resumed.saveState());
    std::printf(
        "[measured] ghost resume in memory: %zu particles (%zu liquid, %zu air, %zu solid), "
        "%llu steps, emitted %zu, killed %zu, first difference: '%s'\n",
        whole.particles().size(), whole.count(ParticleKind::Liquid),
        whole.count(ParticleKind::GhostAir), whole.count(ParticleKind::GhostSolid),
        static_cast<unsigned long long>(whole.stepCount()), whole.emittedCount(),
        whole.killedCount(), difference.c_str());
    // Exact: the same operations on the same bits, in the same order (STYLE.md rule 6).
    EXPECT_EQ(difference, "");
    EXPECT_EQ(whole.time(), resumed.time());
    EXPECT_EQ(whole.stepCount(), resumed.stepCount());
    // The scene must exercise what it claims to: emission, the kill box, the air layer.
    EXPECT_GT(whole.emittedCount(), 0u);
    EXPECT_GT(whole.killedCount(), 0u);
    EXPECT_GT(whole.count(ParticleKind::GhostAir), 0u);

    // The test has teeth: a continuation from a state with one value changed differs. The
    // max acceleration enters only through the CFL force limit, which binds above ~1600 m/s^2
    // here (0.4 sqrt(h / a) < 0.4 h / c), hence the large value.
    GhostSolver right(scene.settings);
    right.restoreState(saved);
    scene.addInputs(right);
    right.advanceFrame();
    const SolverState reference = right.saveState();
    for (const char* key : {"max_acceleration", "step"}) {
        SolverState changed = saved;
        if (changed.reals.count(key)) changed.reals[key] = 1e6;
        else changed.integers[key] = 0;
        GhostSolver wrong(scene.settings);
        wrong.restoreState(changed);
        scene.addInputs(wrong);
        wrong.advanceFrame();
        EXPECT_NE(firstDifference(reference, wrong.saveState()), "") << key;
    }
}

TEST(Resume, RestoreContract)
{
    const Scene scene(Method::Ghost, 4);
    GhostSolver original(scene.settings);
    scene.addInputs(original);
    original.addLiquid(scene.liquid);
    original.step(Real(1) / 600);
    const SolverState saved = original.saveState();
    EXPECT_EQ(saved.solver, "ghost");
    for (const char* key : {"time", "particle_mass", "lennard_jones", "max_acceleration"}) {
        EXPECT_EQ(saved.reals.count(key), 1u) << key;
    }
    for (const char* key :
         {"step", "frame", "initialized", "emitted", "killed", "solids", "emitters"}) {
        EXPECT_EQ(saved.integers.count(key), 1u) << key;
    }

    // Another method.
    GhostSolver basic(ghostfx::testing::withMethod(scene.settings, Method::Basic));
    EXPECT_THAT(ghostfx::testing::errorOf<ValueError>([&] { basic.restoreState(saved); }),
                ::testing::HasSubstr("saved by the 'ghost' solver, this solver runs 'basic'"));

    // Liquid after a restore.
    GhostSolver resumed(scene.settings);
    resumed.restoreState(saved);
    try {
        resumed.addLiquid(scene.liquid);
        FAIL() << "addLiquid after restoreState must throw";
    } catch (const ValueError& e) {
        EXPECT_NE(std::string(e.what()).find("cannot add liquid after restoreState()"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(resumed.addLiquidParticles({Vec3(0)}), ValueError);

    // Stepping before the solids and emitters were added again.
    try {
        resumed.step(Real(1) / 600);
        FAIL() << "stepping without the restored solids must throw";
    } catch (const ValueError& e) {
        EXPECT_NE(std::string(e.what()).find("the restored state has 1 solids but 0 were added"),
                  std::string::npos)
            << e.what();
    }

    // Restore into a solver that already has inputs, or twice.
    GhostSolver busy(scene.settings);
    scene.addInputs(busy);
    EXPECT_THROW(busy.restoreState(saved), ValueError);
    EXPECT_THROW(resumed.restoreState(saved), ValueError);

    // A state missing a key names it.
    SolverState incomplete = saved;
    incomplete.reals.erase("max_acceleration");
    GhostSolver fresh(scene.settings);
    try {
        fresh.restoreState(incomplete);
        FAIL() << "a state without max_acceleration must be refused";
    } catch (const ValueError& e) {
        EXPECT_NE(std::string(e.what()).find("missing real 'max_acceleration'"), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fresh.particles().size() > 0); // untouched by the refused restore
}

TEST(Channels, OnlyWhatTheSceneRequires)
{
    // Liquid-only Ghost SPH: air channels, no solid channels, no solid particles.
    const Scene scene(Method::Ghost, 10);
    GhostSolver liquidOnly(scene.settings);
    liquidOnly.addLiquid(scene.liquid);
    liquidOnly.advanceFrame();
    const ParticleSet& p = liquidOnly.particles();
    EXPECT_EQ(p.vectorChannelNames(), (std::vector<std::string>{"vstar"}));
    EXPECT_EQ(p.scalarChannelNames(),
              (std::vector<std::string>{"air_target", "air_weight", "birth_time"}));
    EXPECT_EQ(liquidOnly.count(ParticleKind::GhostSolid), 0u);
    EXPECT_EQ(liquidOnly.count(ParticleKind::Boundary), 0u);
    EXPECT_GT(liquidOnly.count(ParticleKind::GhostAir), 0u);

    // Basic SPH with a static solid: boundary particles, in their own set with only the static
    // solid channels (the liquid carries none); no air of any kind.
    GhostSettings basicSettings = scene.settings;
    basicSettings.method = Method::Basic;
    GhostSolver basic(basicSettings);
    basic.addSolid(scene.floor);
    basic.addLiquid(scene.liquid);
    basic.advanceFrame();
    const ParticleSet& q = basic.particles();
    EXPECT_EQ(q.vectorChannelNames(), (std::vector<std::string>{"vstar"}));
    EXPECT_EQ(q.scalarChannelNames(), (std::vector<std::string>{"birth_time"}));
    const ParticleSet solids = basic.solidParticles();
    EXPECT_EQ(solids.vectorChannelNames(), (std::vector<std::string>{"normal"}));
    EXPECT_EQ(solids.scalarChannelNames(), (std::vector<std::string>{"solid_index"}));
    EXPECT_EQ(solids.size(), basic.count(ParticleKind::Boundary));
    EXPECT_EQ(basic.count(ParticleKind::GhostAir), 0u);
    EXPECT_EQ(basic.count(ParticleKind::GhostSolid), 0u);
    EXPECT_GT(basic.count(ParticleKind::Boundary), 0u);

    // A moving solid's particles also carry their place, normal and velocity in the solid's frame.
    GhostSolver paddle(scene.settings);
    paddle.addSolid(scene.floor, Vec3(Real(0.1), 0, 0));
    paddle.addLiquid(scene.liquid);
    paddle.advanceFrame();
    EXPECT_EQ(paddle.solidParticles().vectorChannelNames(),
              (std::vector<std::string>{"normal", "solid_n", "solid_v", "solid_x"}));

    // Basic SPH, liquid only: v* and the birth times (sph::BIRTH_TIME_CHANNEL, for "age").
    GhostSolver bare(basicSettings);
    bare.addLiquid(scene.liquid);
    bare.advanceFrame();
    EXPECT_EQ(bare.particles().vectorChannelNames(), (std::vector<std::string>{"vstar"}));
    EXPECT_EQ(bare.particles().scalarChannelNames(), (std::vector<std::string>{"birth_time"}));

    // Bytes per particle of the particle storage: built-in channels 2 Vec3 + 3 Real + kind + id,
    // plus the named ones.
    const double builtIn = 2 * sizeof(Vec3) + 3 * sizeof(Real) + 1 + sizeof(ParticleId);
    auto perParticle = [](const ParticleSet& s) {
        return double(s.memoryBytes()) / double(s.size());
    };
    const double ghostSize = builtIn + sizeof(Vec3) + 3 * sizeof(Real);
    const double staticSolidSize = builtIn + sizeof(Vec3) + sizeof(Real);
    std::printf("[measured] bytes per particle: ghost liquid-only %.1f (size-based %.0f), static "
                "solid particles %.1f (%.0f), basic liquid-only %.1f (%.0f)\n",
                perParticle(liquidOnly.particles()), ghostSize, perParticle(solids),
                staticSolidSize, perParticle(bare.particles()),
                builtIn + sizeof(Vec3) + sizeof(Real));
    // memoryBytes counts capacity: at least the size-based bytes, and at most twice that
    // (vectors grow by doubling), plus the scratch of a sort that may be a little larger.
    EXPECT_GE(perParticle(liquidOnly.particles()), ghostSize);
    EXPECT_LE(perParticle(liquidOnly.particles()), 2.5 * ghostSize);
    EXPECT_GE(perParticle(solids), staticSolidSize);
    EXPECT_LE(perParticle(solids), 2.5 * staticSolidSize);
}

TEST(StepObserver, CalledAfterEveryStepWithItsDt)
{
    const Scene scene(Method::Ghost, 10);
    GhostSolver solver(scene.settings);
    solver.addLiquid(scene.liquid);
    std::vector<Real> dts;
    std::vector<std::uint64_t> steps;
    solver.setStepObserver([&](const GhostSolver& s, Real dt) {
        dts.push_back(dt);
        steps.push_back(s.stepCount());
    });
    solver.advanceFrame();
    ASSERT_EQ(dts.size(), 10u);
    for (std::size_t k = 0; k < steps.size(); ++k) {
        EXPECT_EQ(steps[k], k + 1); // called after the step completed
        EXPECT_EQ(dts[k], Real(1) / (Real(60) * Real(10)));
    }

    // An observer that throws (an interrupt) stops the run after a complete step.
    solver.setStepObserver([](const GhostSolver&, Real) { throw std::runtime_error("interrupt"); });
    EXPECT_THROW(solver.advanceFrame(), std::runtime_error);
    EXPECT_EQ(solver.stepCount(), 11u);
    solver.setStepObserver({});
    solver.step(Real(1) / 600);
    EXPECT_EQ(solver.stepCount(), 12u);
}

TEST(SolidParticles, CarryTheStepWhereLiquidReachesAndRestValuesElsewhere)
{
    // A ghost solid takes the density, pressure and Eq. 3 velocity of its nearest liquid
    // particle ([SB12] Algorithm 3) only while liquid reaches it; the block keeps these in its
    // own channels, so every other solid particle must show rest values, and a checkpoint
    // stores rest values everywhere (the extrapolation is the step's scratch).
    const Scene scene(Method::Ghost, 0);
    GhostSolver solver(scene.settings);
    scene.start(solver, 2);

    const Real rho0 = scene.settings.restDensity, R = scene.settings.supportRadius();
    std::vector<Vec3> liquid;
    const ParticleSet& fluid = solver.particles();
    for (std::size_t i = 0; i < fluid.size(); ++i) {
        if (fluid.kinds()[i] == ParticleKind::Liquid) liquid.push_back(fluid.positions()[i]);
    }
    auto atRest = [rho0](const ParticleSet& set, std::size_t i) {
        const Vec3 vs = set.hasVectorChannel("solid_v") ? set.vectorChannel("solid_v")[i] : Vec3(0);
        return set.densities()[i] == rho0 && set.pressures()[i] == Real(0)
               && set.velocities()[i] == vs;
    };
    const ParticleSet solids = solver.solidParticles();
    std::size_t far = 0, farMoved = 0, extrapolated = 0;
    for (std::size_t i = 0; i < solids.size(); ++i) {
        Real nearest2 = std::numeric_limits<Real>::max();
        for (const Vec3& y : liquid)
            nearest2 = std::min(nearest2, (solids.positions()[i] - y).lengthSqr());
        const bool rest = atRest(solids, i);
        extrapolated += !rest;
        // Liquid moves far less than R in the step since the extrapolation; 2R leaves room.
        if (nearest2 > sqr(2 * R)) {
            ++far;
            farMoved += !rest;
        }
    }
    std::printf("[measured] solid particles %zu: %zu carry the step's values, %zu farther than 2R "
                "from liquid (%zu of them not at rest)\n",
                solids.size(), extrapolated, far, farMoved);
    EXPECT_GT(extrapolated, 0u);
    EXPECT_GT(far, 0u);
    EXPECT_EQ(farMoved, 0u);

    const SolverState state = solver.saveState();
    std::size_t savedSolids = 0, savedMoved = 0;
    for (std::size_t i = 0; i < state.particles.size(); ++i) {
        if (state.particles.kinds()[i] != ParticleKind::GhostSolid) continue;
        ++savedSolids;
        savedMoved += !atRest(state.particles, i);
    }
    EXPECT_EQ(savedSolids, solids.size());
    EXPECT_EQ(savedMoved, 0u);
}
