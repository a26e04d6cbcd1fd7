/// @file   StopSignals.h
/// @brief  The signals that ask a run to stop at the end of its frame: Ctrl-C (SIGINT) and the
///         SIGTERM and SIGUSR1 that render farms send before they pre-empt or time out a job.
/// @details The first of them asks the run to finish the frame it is simulating, write its
///          outputs and a checkpoint, and stop with exit code 128 + the signal's number (130,
///          143, 138). The handler then gives all three their default action back, so a second
///          signal ends the process at once; every file is written atomically, so nothing is left
///          half-written either way. Slurm (`--signal=USR1@60`), Deadline and OpenCue send one
///          of these ahead of the hard kill (README, "On a render farm").
#pragma once

namespace ghostfx {
namespace cmd {

class StopSignals
{
public:
    /// Catch SIGINT, SIGTERM and SIGUSR1 while this object lives; the previous actions come
    /// back when it dies. `leaveHandled`: keep any signal whose action is not the default (a
    /// Python script's own handlers, and the interpreter's for SIGINT).
    explicit StopSignals(bool leaveHandled = false);
    ~StopSignals();
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;

    /// The first stop signal caught since construction (SIGINT, SIGTERM, SIGUSR1), or 0.
    static int received();

    /// The exit code of a run stopped by `signal`: 128 + its number, as a shell reports it.
    static int exitCode(int signal) { return 128 + signal; }
    /// "SIGINT (Ctrl-C)", "SIGTERM", "SIGUSR1".
    static const char* describe(int signal);

private:
    bool mInstalled[3] = {false, false, false};
};

} // namespace cmd
} // namespace ghostfx
