/// @file   BasicPressure.h
/// @brief  The "Basic SPH" baseline of [SB12] Sec. 3 as a pressure model (BasicPressure.cc).
#pragma once

#include "TaitPressure.h"

namespace ghostfx {
namespace ghost {

/// Tait's equation of state with [SB12] Sec. 3's forces: Becker and Teschner's viscosity,
/// Lennard-Jones walls and XSPH on the positions.
class BasicPressure final : public TaitEquationOfState
{
public:
    std::string name() const override { return "basic"; }
    void step(LiquidStep& step, Real dt) override;

private:
    /// v* = v + dt (g + pressure, viscosity and Lennard-Jones forces) of the liquid.
    void accelerate(LiquidStep& step, Real dt);
    /// XSPH on the positions, which take v*; the liquid's velocities too.
    void move(LiquidStep& step, Real dt);
};

} // namespace ghost
} // namespace ghostfx
