/// @file   BasicPressure.h
/// @brief  The "Basic SPH" baseline of [SB12] Sec. 3 as a pressure model (BasicPressure.cc).
#pragma once

#include "TaitPressure.h"

#include <vector>

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
    /// The channels of the liquid (and boundary-free set) the step's passes read and write.
    struct Channels
    {
        explicit Channels(sph::ParticleSet& set);
        std::size_t n;
        std::vector<Vec3>& x;
        const std::vector<Real>& m;
        const std::vector<Real>& rho;
        const std::vector<Real>& p;
        const std::vector<sph::ParticleKind>& kind;
        std::vector<Vec3>& v;
        std::vector<Vec3>& vnew; ///< v* (LiquidStep::VELOCITY_STAR)
    };
    /// v* = v + dt (g + pressure, viscosity and Lennard-Jones forces) of the liquid.
    void accelerate(LiquidStep& step, Real dt, const Channels& ch);
    /// XSPH on the positions, which take v*; the liquid's velocities too.
    void move(LiquidStep& step, Real dt, const Channels& ch);
};

} // namespace ghost
} // namespace ghostfx
