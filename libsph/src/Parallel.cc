/// @file   Parallel.cc
/// @brief  Serial switch and thread cap behind Parallel.h.
#include "ghostfx/sph/Parallel.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace ghostfx {
namespace parallel {

namespace {

bool serialFromEnvironment()
{
    const char* value = std::getenv("GHOSTFX_SERIAL");
    return value != nullptr && *value != '\0' && std::strcmp(value, "0") != 0;
}

std::atomic<bool>& serialFlag()
{
    static std::atomic<bool> flag{serialFromEnvironment()};
    return flag;
}

} // namespace

void setSerial(bool serial) { serialFlag().store(serial); }

bool isSerial() { return serialFlag().load(std::memory_order_relaxed); }

ThreadLimit::ThreadLimit(int maxThreads)
{
    if (maxThreads > 0) {
        mControl = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, std::size_t(maxThreads));
    }
}

ThreadLimit::~ThreadLimit() = default;

int maxThreads()
{
    if (isSerial()) return 1;
    return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

} // namespace parallel
} // namespace ghostfx
