/// @file   BasicPressure.h
/// @brief  The "Basic SPH" baseline of [SB12] Sec. 3 as a pressure model (BasicPressure.cc).
#pragma once

#include "ghostfx/ghost/LiquidStep.h"
#include "ghostfx/ghost/PressureSolver.h"

#include <vector>

namespace ghostfx {
namespace ghost {

class BasicPressure final : public PressureSolver
{
public:
    std::string name() const override { return "basic"; }
    /// Tait's equation, as TaitPressure.
    bool pressureFromDensity(LiquidStep& step) override;
    void step(LiquidStep& step, Real dt) override;

private:
    /// v* = v + dt (g + pressure, viscosity and Lennard-Jones forces) of the liquid.
    void accelerate(LiquidStep& step, Real dt);
    /// XSPH on the positions, which take v*; the liquid's velocities too.
    void move(LiquidStep& step, Real dt);
};

} // namespace ghost
} // namespace ghostfx
