/// @file   StopSignals.cc
/// @brief  The stop signals' handler (StopSignals.h), with sigaction so its behaviour does not
///         depend on the C library's signal() flavour.
#include "StopSignals.h"

#include <atomic>
#include <csignal>
#include <signal.h>

namespace ghostfx {
namespace cmd {

namespace {

constexpr int SIGNALS[3] = {SIGINT, SIGTERM, SIGUSR1};

std::atomic<int> gReceived{0};
/// Which of SIGNALS the handler is installed for, and what they had before.
std::atomic<bool> gCaught[3];
struct sigaction gPrevious[3];

extern "C" void onStopSignal(int signal)
{
    int none = 0;
    gReceived.compare_exchange_strong(none, signal);
    // A second signal ends the process at once (sigaction is async-signal-safe).
    struct sigaction fallback = {};
    fallback.sa_handler = SIG_DFL;
    sigemptyset(&fallback.sa_mask);
    for (int k = 0; k < 3; ++k) {
        if (gCaught[k].load()) ::sigaction(SIGNALS[k], &fallback, nullptr);
    }
}

} // namespace

StopSignals::StopSignals(bool leaveHandled)
{
    static_assert(std::atomic<int>::is_always_lock_free, "the handler stores an atomic int");
    gReceived.store(0);
    struct sigaction action = {};
    action.sa_handler = onStopSignal;
    sigemptyset(&action.sa_mask);
    for (int k = 0; k < 3; ++k) {
        struct sigaction current = {};
        ::sigaction(SIGNALS[k], nullptr, &current);
        if (leaveHandled && current.sa_handler != SIG_DFL) continue;
        gCaught[k].store(true);
        if (::sigaction(SIGNALS[k], &action, &gPrevious[k]) == 0) mInstalled[k] = true;
        else gCaught[k].store(false);
    }
}

StopSignals::~StopSignals()
{
    for (int k = 0; k < 3; ++k) {
        if (!mInstalled[k]) continue;
        gCaught[k].store(false);
        ::sigaction(SIGNALS[k], &gPrevious[k], nullptr);
    }
}

int StopSignals::received() { return gReceived.load(); }

const char* StopSignals::describe(int signal)
{
    switch (signal) {
    case SIGINT: return "SIGINT (Ctrl-C)";
    case SIGTERM: return "SIGTERM";
    case SIGUSR1: return "SIGUSR1";
    default: return "a signal";
    }
}

} // namespace cmd
} // namespace ghostfx
