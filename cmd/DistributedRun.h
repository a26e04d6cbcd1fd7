/// @file   DistributedRun.h
/// @brief  `mpirun -np N ghostfx run scene.json`: one simulation over N processes.
/// @details Every process reads the scene and builds the same simulation and first state; the
///          domain is then cut into slabs balanced by particle count (sph::DomainDecomposition),
///          each process keeps its slab's particles and exchanges halos with its neighbours
///          every step (dist::MpiExchange). Rank 0 writes the frames from every rank's liquid,
///          gathered per frame. Built with GHOSTFX_MPI; a build without it refuses to run as
///          more than one process (each would write the same files).
#pragma once

#include "FrameWriter.h"
#include "Simulation.h"

#include <ghostfx/vdbio/Scene.h>

#include <memory>
#include <string>

namespace ghostfx {
namespace cmd {

class DistributedRun
{
public:
    /// A run over the processes an MPI launcher started, or null for a single process.
    static std::unique_ptr<DistributedRun> startIfLaunched();
    virtual ~DistributedRun() = default;

    virtual int rank() const = 0;
    virtual int ranks() const = 0;
    bool root() const { return rank() == 0; }

    /// Share `sim`'s first state among the processes (Simulation::prepareToShare, share).
    virtual void share(Simulation& sim) = 0;
    /// Every process's liquid for the frame's outputs, on rank 0; elsewhere an empty snapshot.
    /// Collective: every process calls it for every frame.
    virtual FrameSnapshot snapshot(const vdbio::SceneOutputs& outputs, const Simulation& sim,
                                   int frame) = 0;
    /// "N liquid, M air on R processes" summed over the processes. Collective.
    virtual std::string counts(const Simulation& sim) = 0;
    /// Whether any process says yes (an interrupt seen by one stops all at the same frame).
    /// Collective.
    virtual bool any(bool yes) = 0;
};

/// After an error on this process during a run over several: stop them all (MPI_Abort), so
/// none waits for this one forever. Does nothing for a single process.
void abortDistributedRun(int code);

} // namespace cmd
} // namespace ghostfx
