/// @file   DistributedRun.h
/// @brief  `mpirun -np N ghostfx run scene.json`: one simulation over N processes.
/// @details Every process reads the scene and builds the same simulation and first state; the
///          domain is then cut into slabs balanced by particle count (sph::DomainDecomposition),
///          each process keeps its slab's particles and exchanges halos with its neighbours
///          every step (dist::MpiExchange). Each process builds its region's part of every
///          frame grid and rank 0 merges and writes them (DistributedFrames.h). Built with GHOSTFX_MPI; a build without it refuses to run as
///          more than one process (each would write the same files).
#pragma once

#include "FrameWriter.h"
#include "Simulation.h"

#include <ghostfx/vdbio/Scene.h>
#include <ghostfx/vdbio/Stats.h>

#include <memory>
#include <string>
#include <vector>

namespace ghostfx {
namespace cmd {

/// A checkpoint of a run over several processes: one state file per process (the usual
/// checkpoint format) and a manifest naming them, with the processes' regions.
struct DistributedManifest
{
    int frame = 0;
    int ranks = 0;
    std::vector<std::string> files;    ///< per rank, absolute (relative in the file)
    std::vector<double> decomposition; ///< sph::DomainDecomposition::save()
};

/// One state for the whole simulation from the states its processes saved (a manifest's
/// files, in rank order): the first process's state with every other process's liquid and air
/// appended (solids are whole in each, so they are taken once), the emitted and killed counts
/// summed, the largest acceleration the largest. A one-process run continues from it, and a
/// run over any number of processes cuts it anew (DistributedRun::share).
sph::SolverState mergeProcessStates(std::vector<sph::SolverState> states);

/// Whether a --resume path is a manifest (".ranks.json") rather than one process's state.
bool isDistributedManifest(const std::string& path);
/// Read and check a manifest; a SceneError names the file and what is wrong.
DistributedManifest readDistributedManifest(const std::string& path);
/// The manifest and the per-process files of the checkpoint a single run would write at
/// `h5Path` (checkpoint.0012.h5 -> checkpoint.0012.ranks.json, checkpoint.0012.rank1.h5).
std::string manifestPath(const std::string& h5Path);
std::string rankCheckpointPath(const std::string& h5Path, int rank);

class DistributedRun
{
public:
    /// A run over the processes an MPI launcher started, or null for a single process.
    static std::unique_ptr<DistributedRun> startIfLaunched();
    virtual ~DistributedRun() = default;

    virtual int rank() const = 0;
    virtual int ranks() const = 0;
    bool root() const { return rank() == 0; }

    /// Share `sim`'s first state among the processes (Simulation::prepareToShare, share); a
    /// simulation restored from this process's part of a checkpoint keeps the checkpoint's
    /// regions (`savedParts`, DistributedManifest::decomposition).
    virtual void share(Simulation& sim, const std::vector<double>* savedParts = nullptr) = 0;
    /// Write this process's state and (rank 0) the manifest; returns the manifest's path, the
    /// one to resume from. Collective.
    virtual std::string writeCheckpoint(const std::string& h5Path, const Simulation& sim,
                                        const std::string& fingerprint, int frame) = 0;
    /// The frame's grids built in pieces and merged (DistributedFrames.h), on rank 0 with no
    /// particles; elsewhere an empty snapshot. Collective: every process calls it every frame.
    virtual FrameSnapshot snapshot(const vdbio::SceneOutputs& outputs, const Simulation& sim,
                                   int frame) = 0;
    /// "N liquid, M air on R processes" summed over the processes. Collective.
    virtual std::string counts(const Simulation& sim) = 0;
    /// Whether any process says yes (an interrupt seen by one stops all at the same frame).
    /// Collective.
    virtual bool any(bool yes) = 0;
    virtual double sumOf(double value) = 0;
    virtual double maxOf(double value) = 0;

    /// One statistics row for the whole simulation from every process's own row (same
    /// columns everywhere). Collective. Counts of liquid and air are summed, counts of solid
    /// particles taken once (solids are whole on every process), `density_error_mean`
    /// weighted by the processes' liquid; every other column is the largest over the
    /// processes: maxima, the slowest process's phase times, the heaviest process's
    /// `bytes_per_particle` (frame, step, time and dt are the same everywhere).
    vdbio::StatsRow combine(const vdbio::StatsRow& mine);
};

/// After an error on this process during a run over several: stop them all (MPI_Abort), so
/// none waits for this one forever. Does nothing for a single process.
void abortDistributedRun(int code);

/// Wait for an error of another process that this one knows is coming (every process found
/// the same fault, and one of them reports it): a barrier of all the processes that the
/// reporting one never joins, left when its abortDistributedRun stops this one. Does nothing
/// for a single process.
void awaitDistributedAbort();

} // namespace cmd
} // namespace ghostfx
