/// @file   Timing.h
/// @brief  Wall-clock seconds for phase timings and progress, one definition for every solver.
#pragma once

#include <chrono>

namespace ghostfx {
namespace sph {

/// Seconds from `start` to now on the steady clock.
inline double secondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace sph
} // namespace ghostfx
