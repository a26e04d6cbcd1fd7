/// @file   BenchCommon.h
/// @brief  Benchmarks' clocks: wall time and the CPU time of the whole process.
#pragma once

#include <chrono>

#include <sys/resource.h>

namespace ghostfx {
namespace bench {

/// Monotonic wall clock (s), for differences.
inline double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

/// User + system CPU time of every thread of this process so far (s).
inline double processCpuSeconds()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec)
           + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

} // namespace bench
} // namespace ghostfx
