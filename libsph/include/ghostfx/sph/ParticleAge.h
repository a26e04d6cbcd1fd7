/// @file   ParticleAge.h
/// @brief  Each particle's birth time, kept as a named channel so exporters can write its age.
/// @details The channel BIRTH_TIME_CHANNEL holds the simulation time (s) at which a particle was
///          added to its set. A solver calls ensureBirthTimes() when it is built and after a
///          resume, and stampBirthTimes() at the start of every step (the gas solver also at
///          its end, for boiling vapour added between its steps): the channel's default becomes
///          the current time, so every particle added (emitters, gas sources, vapour, resampled
///          ghost air) is stamped by ParticleSet::add / addBatch with no code at the place it
///          is made. A resumed set keeps the default its checkpoint saved, so particles added
///          before its next step are stamped as in the run that never stopped. Split daughters
///          copy their mother's value and merged particles take the mass-weighted mean of their
///          parts' (gas SplitMerge copies every channel). Only exporters read the channel: no
///          solver pass depends on it, so it changes no result.
#pragma once

#include "ghostfx/sph/ParticleSet.h"

namespace ghostfx {
namespace sph {

/// Scalar channel of the time (s) a particle was added to its set.
constexpr const char* BIRTH_TIME_CHANNEL = "birth_time";

/// Make particles added to `set` from now on count as born at `time` (s), giving the set the
/// channel first if it lacks it (ensureBirthTimes).
void stampBirthTimes(ParticleSet& set, double time);

/// Give `set` the channel if it lacks it, its particles (and those added later) all born at
/// `time` (s): a fresh solver's initial particles, or a state saved without birth times, whose
/// ages then count from the resume. A set that has the channel keeps its values and default.
void ensureBirthTimes(ParticleSet& set, double time);

} // namespace sph
} // namespace ghostfx
