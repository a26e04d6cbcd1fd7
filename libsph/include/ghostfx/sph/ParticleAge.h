/// @file   ParticleAge.h
/// @brief  Each particle's birth time, kept as a named channel so exporters can write its age.
/// @details The channel BIRTH_TIME_CHANNEL holds the simulation time (s) at which a particle was
///          added to its set. A solver calls stampBirthTimes() when it is built, after a resume
///          and at the start of every step: the channel's default becomes the current time, so
///          every particle the step adds (emitters, gas sources, boiling vapour, resampled
///          ghost air) is stamped by ParticleSet::add / addBatch with no code at the place it is
///          made. Split daughters copy their mother's value and merged particles take the
///          mass-weighted mean of their parts' (gas SplitMerge copies every channel). Only
///          exporters read the channel: no solver pass depends on it, so it changes no result.
#pragma once

#include "ghostfx/sph/ParticleSet.h"

namespace ghostfx {
namespace sph {

/// Scalar channel of the time (s) a particle was added to its set.
constexpr const char* BIRTH_TIME_CHANNEL = "birth_time";

/// Make particles added to `set` from now on count as born at `time` (s). A set without the
/// channel gets it, its particles all born at `time` (a fresh solver's initial particles, or a
/// state saved without birth times: their age counts from the resume).
void stampBirthTimes(ParticleSet& set, double time);

} // namespace sph
} // namespace ghostfx
