/// @file   ResumeScene.h
/// @brief  The small liquid scene the resume tests share (in memory and through a checkpoint).
#pragma once

#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

namespace ghostfx {
namespace testing {

/// A scene that takes every path of the liquid solver's state: a block of liquid on a floor
/// that slides sideways (moving solid), a nozzle pouring into it (emitter: first filled, then
/// grown from seeds), a kill box through the liquid's right side (killed counter) and, for
/// Ghost SPH, air resampled every 10 steps, so a frame boundary or a checkpoint falls in the
/// middle of an air fade. Spacing 1 cm, 60 fps.
struct ResumeScene
{
    static constexpr sph::Real H = sph::Real(0.01);

    ghost::GhostSettings settings;
    sph::LevelSet floor, liquid, nozzle;
    sph::Vec3 floorVelocity{0};

    /// `substeps` 0: CFL-adaptive steps, which read the saved maximum acceleration.
    ResumeScene(ghost::Method method, int substeps, const sph::Vec3& floorVelocity_,
                std::uint64_t seed)
        : floor(box(sph::Vec3(-0.1f, -0.05f, -0.05f), sph::Vec3(0.1f, 0.0f, 0.05f), "floor"))
        , liquid(box(sph::Vec3(-0.05f, 0.0f, -0.03f), sph::Vec3(0.05f, 0.05f, 0.03f), "liquid"))
        , nozzle(box(sph::Vec3(-0.02f, 0.08f, -0.02f), sph::Vec3(0.02f, 0.1f, 0.02f), "nozzle"))
        , floorVelocity(floorVelocity_)
    {
        settings.method = method;
        settings.spacing = H;
        settings.frameRate = 60;
        settings.substeps = substeps;
        settings.seed = seed;
        settings.killBox = sph::Aabb{sph::Vec3(-0.2f, -0.2f, -0.2f), sph::Vec3(0.04f, 0.3f, 0.2f)};
    }

    /// Add the solids and emitters, in the same order for a fresh and a resumed solver.
    void addInputs(ghost::GhostSolver& solver) const
    {
        solver.addSolid(floor, floorVelocity);
        solver.addEmitter(nozzle, sph::Vec3(0, sph::Real(-0.5), 0));
    }

    /// Start a fresh `solver` (the inputs, then the liquid) and advance it `frames` frames.
    void start(ghost::GhostSolver& solver, int frames) const
    {
        addInputs(solver);
        solver.addLiquid(liquid);
        for (int f = 0; f < frames; ++f) solver.advanceFrame();
    }

private:
    static sph::LevelSet box(const sph::Vec3& lo, const sph::Vec3& hi, const char* name)
    {
        return sph::makeLevelSet(sph::makeBoxLevelSet(lo, hi, H / 2), name);
    }
};

} // namespace testing
} // namespace ghostfx
