/// @file   ParticleAge.cc
#include "ghostfx/sph/ParticleAge.h"

namespace ghostfx {
namespace sph {

void stampBirthTimes(ParticleSet& set, double time)
{
    set.addScalarChannel(BIRTH_TIME_CHANNEL, Real(time));
    set.setScalarChannelDefault(BIRTH_TIME_CHANNEL, Real(time));
}

void ensureBirthTimes(ParticleSet& set, double time)
{
    set.addScalarChannel(BIRTH_TIME_CHANNEL, Real(time));
}

} // namespace sph
} // namespace ghostfx
