/// @file   DistributedRunNone.cc
/// @brief  DistributedRun in a build without MPI: one process, and a clear refusal of more.
#include "DistributedRun.h"

#include <ghostfx/sph/Exceptions.h>

#include <cstdlib>

namespace ghostfx {
namespace cmd {

std::unique_ptr<DistributedRun> DistributedRun::startIfLaunched()
{
    // Open MPI's mpirun and the PMI launchers say how many processes they started.
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
        const char* value = std::getenv(name);
        if (value && std::atoi(value) > 1) {
            throw ValueError(msg("started as ", value,
                                 " processes, but this ghostfx was built without MPI (each "
                                 "would simulate and write the whole scene): run one process, "
                                 "or build with -DGHOSTFX_MPI=ON"));
        }
    }
    return nullptr;
}

void abortDistributedRun(int /*code*/) {}

void awaitDistributedAbort() {}

} // namespace cmd
} // namespace ghostfx
