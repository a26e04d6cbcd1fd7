/// @file   FrameSteps.h
/// @brief  One frame of time steps, shared by every solver's frame loop: fixed substeps, or
///         CFL-limited steps that land exactly on the frame's end.
#pragma once

#include <ghostfx/sph/SolverState.h>
#include <ghostfx/sph/Types.h>

namespace ghostfx {
namespace sph {

/// Time (s) left before a frame's end below which stepFrame() takes no further step.
inline double frameEndTolerance(Real frameRate) { return 1e-6 / double(frameRate); }

/// Advance from `time()` to `frameEnd` (s). With `substeps` > 0: that many steps of
/// 1 / (frameRate substeps). With 0: steps of `stableStep()`, the last one shortened or
/// stretched to land on the frame's end. Steps are Real and clocks double, so float rounding
/// leaves a remainder of ~1e-11 s at the end; leftovers below a millionth of the frame are
/// dropped rather than paid for with a whole extra step (the caller sets its clock to frameEnd).
template <typename Time, typename StableStep, typename Step>
void stepFrame(double frameEnd, Real frameRate, int substeps, Time&& time, StableStep&& stableStep,
               Step&& step)
{
    if (substeps > 0) {
        const Real dt = Real(1) / (frameRate * Real(substeps));
        for (int s = 0; s < substeps; ++s) step(dt);
        return;
    }
    const double tolerance = frameEndTolerance(frameRate);
    while (frameEnd - time() > tolerance) {
        const double remaining = frameEnd - time();
        Real dt = stableStep();
        if (double(dt) > remaining - tolerance) dt = Real(remaining);
        step(dt);
    }
}

/// One frame of a solver's run: the steps of stepFrame() from run.time to the next frame's end,
/// then the clock set to that end exactly (no drift from summing substeps) and the frame counted.
template <typename StableStep, typename Step>
void advanceRunOneFrame(RunCounters& run, Real frameRate, int substeps, StableStep&& stableStep,
                        Step&& step)
{
    const double frameEnd = double(run.frame + 1) / double(frameRate);
    stepFrame(
        frameEnd, frameRate, substeps, [&run] { return run.time; }, stableStep, step);
    run.time = frameEnd;
    ++run.frame;
}

} // namespace sph
} // namespace ghostfx
