/// @file   Progress.h
/// @brief  What `ghostfx run` shows while it runs: a progress bar on a terminal (one line
///         redrawn), or a log line per frame, or nothing.
#pragma once

#include "Simulation.h"

#include <chrono>
#include <cstdint>
#include <string>

namespace ghostfx {
namespace cmd {

/// Seconds from `a` to `b`.
double secondsBetween(std::chrono::steady_clock::time_point a,
                      std::chrono::steady_clock::time_point b);
/// "42s", "3m07s", "2h05m".
std::string duration(double seconds);

class Progress
{
public:
    enum class Mode { None, Log, Bar };

    /// The run writes frames `first` to `last`.
    Progress(Mode mode, int first, int last) : mMode(mode), mFirst(first), mLast(last) {}

    /// After a step of `frame` (bar only, at most five redraws a second).
    void step(const Simulation& sim, int frame, int substep);
    void countStep() { ++mSteps; }
    /// After `frame`; `counts`: the particles, as Simulation::counts() (or
    /// DistributedRun::counts()) says.
    void frame(const Simulation& sim, const std::string& counts, int frame, int steps,
               double frameSeconds, bool written);
    /// A line of its own (nothing in Mode::None).
    void message(const std::string& text);

private:
    Mode mMode;
    int mFirst, mLast;
    std::uint64_t mSteps = 0;
    std::chrono::steady_clock::time_point mStart = std::chrono::steady_clock::now(), mLastDraw{};
};

} // namespace cmd
} // namespace ghostfx
