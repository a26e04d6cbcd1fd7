/// @file   GasTemperature.cc
/// @brief  Temperature of the gas [RYY15] Sec. 3.3: settings and the explicit Euler update.
#include "ghostfx/gas/GasTemperature.h"

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

} // namespace gas
} // namespace ghostfx
