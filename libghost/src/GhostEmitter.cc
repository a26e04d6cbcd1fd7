/// @file   GhostEmitter.cc
/// @brief  A continuous liquid source's placement at a step's time and the velocity it gives
///         its liquid ([SB12] Sec. 4.5.2, with the emitter moving rigidly).
/// @details A moving emitter's shape and velocity are given in its own frame. Seen from the
///          emitter the liquid leaves at `velocity` through its cross-section, so the rate is
///          rho0 |velocity| A in any motion; in the world the liquid moves at that velocity
///          rotated with the emitter plus the emitter's own velocity at the liquid's point
///          (translation rate + rotation rate times the point in the emitter's frame), as a
///          nozzle's jet does.
#include "GhostInternal.h"

#include <algorithm>

namespace ghostfx {
namespace ghost {

void GhostSolver::Emitter::placeAt(double time)
{
    if (!moving()) return;
    placement = at(time);
    placedTime = time;
    box = placement.toWorld(shape.bounds());
}

sph::Vec3 GhostSolver::Emitter::liquidVelocity(const sph::Vec3& x) const
{
    if (!moving()) return velocity;
    const sph::Vec3 local = placement.toLocal(x);
    const sph::Vec3 frame = placement.hasRates
                                ? placement.translationRate + placement.rotationRate * local
                                : MovingLevelSet::velocity(local, placedTime);
    return placement.rotation * velocity + frame;
}

void GhostSolver::Emitter::giveVelocities(const std::vector<sph::Vec3>& x,
                                          sph::Vec3* velocities) const
{
    if (!moving()) {
        std::fill(velocities, velocities + x.size(), velocity);
        return;
    }
    for (std::size_t k = 0; k < x.size(); ++k) velocities[k] = liquidVelocity(x[k]);
}

} // namespace ghost
} // namespace ghostfx
