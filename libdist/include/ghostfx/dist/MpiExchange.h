/// @file   MpiExchange.h
/// @brief  sph::ParticleExchange over MPI: one simulation spread over the ranks of a
///         communicator, each owning the particles of one part of a DomainDecomposition.
/// @details Every exchange is one MPI_Alltoall of byte counts and one MPI_Alltoallv of the
///          bytes (only neighbouring parts send anything). Particles travel with every channel
///          of their set (built-in, scalar and vector, by name), so a solver's own channels
///          (air weights, v*) migrate with them. Halo copies are refreshed by id: the owner
///          sends the values of the ids it sent at the last exchange, in the same order, and
///          the receiver finds its copies of those ids; ids are unique across the ranks
///          (GhostSolver::setExchange gives each rank its own id sequence).
///          Rebalancing: when the owned counts' imbalance (largest over mean) passes
///          `rebalanceAbove`, rebalance() (called by exchange()) rebuilds the decomposition from
///          every rank's owned particles (gathered to all ranks: the cuts are then the same
///          everywhere) and migrates accordingly.
#pragma once

#include <ghostfx/sph/DomainDecomposition.h>
#include <ghostfx/sph/ParticleExchange.h>

#include <mpi.h>

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

namespace ghostfx {
namespace dist {

/// MPI_Init on construction (unless already initialised), MPI_Finalize on destruction if
/// this object initialised it. One per program, made before any other MPI use.
class MpiSession
{
public:
    MpiSession(int* argc, char*** argv);
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
    int rank() const;
    int ranks() const;

private:
    bool mOwner = false;
};

/// Whether this program was started by an MPI launcher with more than one process (mpirun,
/// srun): the environment says so before MPI_Init.
int launcherRankCount();

class MpiExchange : public sph::ParticleExchange
{
public:
    /// Parts for the ranks of `comm`: `scheme` over `points` (the same on every rank).
    MpiExchange(MPI_Comm comm, const std::vector<sph::Vec3>& points,
                sph::DecompositionScheme scheme = sph::DecompositionScheme::Slabs);
    /// Parts given (a checkpoint's); their count must be the communicator's size.
    MpiExchange(MPI_Comm comm, sph::DomainDecomposition parts,
                sph::DecompositionScheme scheme = sph::DecompositionScheme::Slabs);

    int rank() const override { return mRank; }
    int ranks() const override { return mRanks; }
    bool owns(const sph::Vec3& x) const override { return mParts.owner(x) == mRank; }
    void exchange(sph::ParticleSet& set, sph::Real width) override;
    void refresh(sph::ParticleSet& set, const std::vector<std::string>& channels) override;
    void dropHalo(sph::ParticleSet& set) override;
    std::vector<sph::Vec3> allPositions(const std::vector<sph::Vec3>& mine) override;
    double maxOf(double value) override;
    double minOf(double value) override;
    double sumOf(double value) override;

    /// The particles of `set` whose kind is in `kinds` (halo copies excluded), from every rank,
    /// on rank `root` (rank order, each rank's in its own order); an empty set elsewhere.
    sph::ParticleSet gather(const sph::ParticleSet& set,
                            const std::vector<sph::ParticleKind>& kinds, int root = 0) const;

    /// This rank's particles of `kinds` (halo copies excluded), then copies of every other
    /// rank's within `width` of this rank's region, without the halo channel: what a frame's
    /// piece for this region needs (DistributedFrames). `own` gets the count of the first part.
    /// Collective.
    sph::ParticleSet surroundings(const sph::ParticleSet& set,
                                  const std::vector<sph::ParticleKind>& kinds, sph::Real width,
                                  std::size_t* own = nullptr) const;

    /// This rank's particles of `kinds` (halo copies excluded) sent each to the rank
    /// `destination` names for it; returns those that arrive here (this rank's own first),
    /// without the halo channel. `sent` gets how many this rank sent away. Collective.
    sph::ParticleSet redistribute(const sph::ParticleSet& set,
                                  const std::vector<sph::ParticleKind>& kinds,
                                  const std::function<int(const sph::Vec3&)>& destination,
                                  std::size_t* sent = nullptr) const;

    /// Every rank's `mine` handed to fn(rank, bytes) on rank `root`: the root's own first,
    /// then the others' in rank order, one message in memory at a time; elsewhere fn is not
    /// called. Collective.
    void collect(const std::string& mine, const std::function<void(int, const std::string&)>& fn,
                 int root = 0) const;

    const sph::DomainDecomposition& decomposition() const { return mParts; }
    /// Rebuild the parts when the owned counts' largest over mean passes this (default
    /// DomainDecomposition::REBALANCE_IMBALANCE; infinity: never).
    void setRebalanceThreshold(double imbalance) { mRebalanceAbove = imbalance; }
    std::uint64_t rebalances() const { return mRebalances; }
    /// Particles migrated to other ranks and halo copies received, over all exchanges so far.
    std::uint64_t migrated() const { return mMigrated; }
    std::uint64_t haloReceived() const { return mHaloReceived; }

private:
    /// Send bytes[q] to every rank q, return what every rank sent here, by source rank.
    std::vector<std::vector<char>> allToAll(const std::vector<std::vector<char>>& bytes) const;
    void migrate(sph::ParticleSet& set);
    void rebalanceIfNeeded(sph::ParticleSet& set);

    MPI_Comm mComm;
    int mRank = 0, mRanks = 1;
    sph::DomainDecomposition mParts;
    sph::DecompositionScheme mScheme;
    double mRebalanceAbove = sph::DomainDecomposition::REBALANCE_IMBALANCE;
    std::vector<std::vector<sph::ParticleId>> mSent;     ///< ids sent as halo, per rank
    std::vector<std::vector<sph::ParticleId>> mReceived; ///< halo ids received, per rank
    /// The ids sent or received at the last exchange -> their row in the set (refresh()).
    std::unordered_map<sph::ParticleId, sph::Index> mWhere;
    std::uint64_t mRebalances = 0, mMigrated = 0, mHaloReceived = 0;
};

} // namespace dist
} // namespace ghostfx
