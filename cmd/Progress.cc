/// @file   Progress.cc
/// @brief  The progress bar and log lines of `ghostfx run` (Progress.h).
#include "Progress.h"

#include <cstdio>

namespace ghostfx {
namespace cmd {

using Clock = std::chrono::steady_clock;

double secondsBetween(Clock::time_point a, Clock::time_point b)
{
    return std::chrono::duration<double>(b - a).count();
}

std::string duration(double s)
{
    char buffer[32];
    if (s < 60) std::snprintf(buffer, sizeof(buffer), "%.0fs", s);
    else if (s < 3600) std::snprintf(buffer, sizeof(buffer), "%dm%02ds", int(s) / 60, int(s) % 60);
    else std::snprintf(buffer, sizeof(buffer), "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
    return buffer;
}

void Progress::step(const Simulation& sim, int frame, int substep)
{
    if (mMode != Mode::Bar) return;
    const auto now = Clock::now();
    if (secondsBetween(mLastDraw, now) < 0.2) return;
    mLastDraw = now;
    const double elapsed = secondsBetween(mStart, now);
    const double rate = elapsed > 0 ? double(mSteps) / elapsed : 0;
    const double done = double(frame - mFirst) + 0.0;
    const double total = double(mLast - mFirst + 1);
    const double eta = done > 0 ? elapsed * (total - done) / done : 0;
    const int width = 24;
    const int filled = int(width * done / total);
    std::fprintf(stderr, "\r\033[Kframe %d/%d [%s%s] substep %d | %s | %.1f steps/s | ETA %s",
                 frame, mLast, std::string(std::size_t(filled), '#').c_str(),
                 std::string(std::size_t(width - filled), '.').c_str(), substep,
                 sim.counts().c_str(), rate, done > 0 ? duration(eta).c_str() : "?");
    std::fflush(stderr);
}

void Progress::frame(const Simulation& sim, const std::string& counts, int frame, int steps,
                     double frameSeconds, bool written)
{
    if (mMode == Mode::None) return;
    if (mMode == Mode::Bar) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "frame %d/%d: t = %.4f s, %d steps, %s, %.2f s%s\n", frame, mLast,
                 sim.time(), steps, counts.c_str(), frameSeconds,
                 written ? "" : " (not written: before the first frame)");
    std::fflush(stderr);
}

void Progress::message(const std::string& text)
{
    if (mMode == Mode::None) return;
    if (mMode == Mode::Bar) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "%s\n", text.c_str());
}

} // namespace cmd
} // namespace ghostfx
