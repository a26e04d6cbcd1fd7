/// @file   GasVorticity.cc
/// @brief  Artificial vorticity [RYY15] Eqs. 25 - 26: settings, channel and the Euler update.
#include "ghostfx/gas/GasVorticity.h"

#include "ghostfx/gas/GasChannels.h"

#include <ghostfx/sph/Parallel.h>

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

void GasVorticity::integrate(Real dt, sph::ParticleSet& particles) const
{
    if (!mEnabled) return;
    const auto& kind = particles.kinds();
    auto& omega = particles.vectorChannel(channel::VORTICITY);
    parallel::forEach(0, particles.size(), [&](std::size_t i) {
        if (kind[i] != sph::ParticleKind::Gas) return;
        omega[i] += dt * mRate[i];
    });
}

} // namespace gas
} // namespace ghostfx
