/// @file   TaitPressure.h
/// @brief  [SB12]'s weakly compressible pressure: Tait's equation of state and Monaghan's
///         symmetric pressure force (Algorithm 3 lines 8-14).
#pragma once

#include "ghostfx/ghost/LiquidStep.h"
#include "ghostfx/ghost/PressureSolver.h"

#include <vector>

namespace ghostfx {
namespace ghost {

/// Tait's equation of state, p = k ((rho / rho0)^7 - 1) (ghost air: rho0, so p = 0), which
/// the Tait step and Basic SPH's share.
class TaitEquationOfState : public PressureSolver
{
public:
    bool pressureFromDensity(LiquidStep& step) override;
};

class TaitPressure final : public TaitEquationOfState
{
public:
    std::string name() const override { return "tait"; }
    void step(LiquidStep& step, Real dt) override;
    std::size_t memoryBytes() const override { return mTerm.capacity() * sizeof(Real); }

private:
    /// Lines 11-14: v* = v + dt (g + the pressure force) of every liquid particle this
    /// process owns; with shifting, each one's sum_j m_j grad W_ij over the same pairs.
    void accelerate(LiquidStep& step, Real dt, std::vector<Vec3>& gradMass);

    std::vector<Real> mTerm; ///< p / rho^2 of each particle, this step
};

} // namespace ghost
} // namespace ghostfx
