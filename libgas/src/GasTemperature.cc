/// @file   GasTemperature.cc
/// @brief  Temperature of the gas [RYY15] Sec. 3.3: settings and the explicit Euler update.
#include "ghostfx/gas/GasTemperature.h"

#include "ghostfx/gas/GasChannels.h"

#include <ghostfx/sph/Parallel.h>

namespace ghostfx {
namespace gas {

GasTemperature::GasTemperature(const GasSettings& settings)
    : mDiffusion(settings.diffusion)
    , mAmbient(settings.ambientTemperature)
    // Radiation models heat lost to the missing air, so only the methods without air have it.
    , mRadiates(settings.method != Method::Ambient && settings.radiationTime > Real(0))
    , mRadiationTime(settings.radiationTime)
    , mBuoyancy(settings.buoyancy)
    , mDirection(settings.buoyancyDirection.unit())
{}

void GasTemperature::integrate(Real dt, sph::ParticleSet& particles) const
{
    const auto& kind = particles.kinds();
    auto& T = particles.scalarChannel(channel::TEMPERATURE);
    parallel::forEach(0, particles.size(), [&](std::size_t i) {
        if (kind[i] != sph::ParticleKind::Gas) return;
        T[i] += dt * mRate[i];
    });
}

} // namespace gas
} // namespace ghostfx
