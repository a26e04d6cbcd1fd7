/// @file   TaitPressure.h
/// @brief  [SB12]'s weakly compressible pressure: Tait's equation of state and Monaghan's
///         symmetric pressure force (Algorithm 3 lines 8-14).
#pragma once

#include "ghostfx/ghost/LiquidStep.h"
#include "ghostfx/ghost/PressureSolver.h"

#include <vector>

namespace ghostfx {
namespace ghost {

class TaitPressure final : public PressureSolver
{
public:
    std::string name() const override { return "tait"; }
    /// p = k ((rho / rho0)^7 - 1) (ghost air: rho0, so p = 0).
    bool pressureFromDensity(LiquidStep& step) override;
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
