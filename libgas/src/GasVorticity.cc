/// @file   GasVorticity.cc
/// @brief  Artificial vorticity [RYY15] Eqs. 25 - 26: settings, channel and the Euler update.
#include "ghostfx/gas/GasVorticity.h"

#include "ghostfx/gas/GasChannels.h"

namespace ghostfx {
namespace gas {

namespace {
/// g of Eq. 25 (m/s^2): gravity, or standard gravity against the buoyancy direction when the
/// gas has no weight.
Vec3 vorticityGravity(const GasSettings& settings)
{
    const Vec3 g = settings.gravity;
    return g.lengthSqr() > Real(0) ? g : Real(-9.81) * settings.buoyancyDirection.unit();
}
} // namespace

GasVorticity::GasVorticity(const GasSettings& settings)
    : mEnabled(settings.vorticity)
    , mGeneration(settings.vorticityGeneration)
    , mStrength(settings.vorticityStrength)
    , mGravity(vorticityGravity(settings))
{}

void GasVorticity::addChannel(sph::ParticleSet& particles) const
{
    if (mEnabled) particles.addVectorChannel(channel::VORTICITY);
}

} // namespace gas
} // namespace ghostfx
