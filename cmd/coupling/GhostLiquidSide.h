/// @file   GhostLiquidSide.h
/// @brief  The Ghost SPH liquid as the [RYY15] phase transition sees it: libgas talks to a liquid
///         through the narrow gas::LiquidSide interface and knows no libghost type (DESIGN.md),
///         so this adapter lives above both libraries, for the boiling simulation, its benchmark
///         and its tests (header only: target ghostfx_liquid_side).
#pragma once

#include <ghostfx/gas/PhaseTransition.h>
#include <ghostfx/ghost/GhostSolver.h>

namespace ghostfx {
namespace coupling {

class GhostLiquidSide : public gas::LiquidSide
{
public:
    explicit GhostLiquidSide(ghost::GhostSolver& solver) : mSolver(solver) {}
    sph::ParticleSet& particles() override { return mSolver.particles(); }
    sph::Real restDensity() const override { return mSolver.settings().restDensity; }
    sph::Real supportRadius() const override { return mSolver.settings().supportRadius(); }
    sph::Real particleMass() const override { return mSolver.particleMass(); }
    void step(sph::Real dt) override { mSolver.step(dt); }

private:
    ghost::GhostSolver& mSolver;
};

} // namespace coupling
} // namespace ghostfx
