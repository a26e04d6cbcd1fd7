/// @file   DistributedRunMpi.cc
/// @brief  DistributedRun over MPI (built with GHOSTFX_MPI).
#include "DistributedRun.h"

#include "DistributedFrames.h"

#include <ghostfx/dist/MpiExchange.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/Checkpoint.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>

namespace ghostfx {
namespace cmd {

namespace {

std::atomic<bool> gActive{false};

class MpiRun : public DistributedRun
{
public:
    MpiRun() : mSession(nullptr, nullptr) { gActive = true; }
    ~MpiRun() override { gActive = false; }

    int rank() const override { return mSession.rank(); }
    int ranks() const override { return mSession.ranks(); }

    void share(Simulation& sim, const std::vector<double>* savedParts) override
    {
        const std::vector<sph::Vec3> points = sim.prepareToShare();
        if (savedParts) {
            mExchange = std::make_unique<dist::MpiExchange>(
                MPI_COMM_WORLD, sph::DomainDecomposition::load(*savedParts, ranks()));
        } else {
            mExchange = std::make_unique<dist::MpiExchange>(MPI_COMM_WORLD, points);
        }
        sim.share(*mExchange, savedParts != nullptr);
    }

    std::string writeCheckpoint(const std::string& h5Path, const Simulation& sim,
                                const std::string& fingerprint, int frame) override
    {
        vdbio::writeCheckpoint(rankCheckpointPath(h5Path, rank()), sim.saveStates().front(),
                               fingerprint, frame);
        mExchange->maxOf(0.0); // every process's file is complete before the manifest names them
        const std::string manifest = manifestPath(h5Path);
        if (root()) {
            nlohmann::json doc;
            doc["ghostfx_distributed_checkpoint"] = 1;
            doc["frame"] = frame;
            doc["ranks"] = ranks();
            for (int r = 0; r < ranks(); ++r)
                doc["files"].push_back(
                    std::filesystem::path(rankCheckpointPath(h5Path, r)).filename().string());
            doc["decomposition"] = mExchange->decomposition().save();
            vdbio::writeTextFile(manifest, doc.dump(1) + "\n", "checkpoint manifest");
        }
        mExchange->maxOf(0.0); // the manifest exists before anyone goes on
        return manifest;
    }

    FrameSnapshot snapshot(const vdbio::SceneOutputs& outputs, const Simulation& sim,
                           int frame) override
    {
        FrameSnapshot s;
        s.frame = frame;
        s.time = sim.time();
        for (OutputMedium m : sim.media()) {
            const bool points = !(m.liquid ? outputs.pointsFile : outputs.gasPointsFile).empty();
            const bool volumes = !(m.liquid ? outputs.volumeFile : outputs.gasVolumeFile).empty();
            const vdbio::PointsOptions po = pointsOptions(m, outputs, s.time);
            const vdbio::VolumeOptions vo = volumeOptions(m, outputs);
            BuiltGrids built =
                buildFrameGrids(*mExchange, *m.particles, m.kinds, points ? &po : nullptr,
                                volumes ? &vo : nullptr, &mPieceCounts);
            // The mesh's surface and velocity, where the volume file does not hold them.
            if (m.liquid && !outputs.meshFile.empty()
                && !(volumes && volumeHoldsMeshGrids(vo))) {
                const vdbio::VolumeOptions mo = meshVolumeOptions(m, outputs);
                built.mesh =
                    buildFrameGrids(*mExchange, *m.particles, m.kinds, nullptr, &mo).volumes;
            }
            if (!root()) continue;
            // The writer reads the grids; the particles stay with their processes.
            auto none = std::make_shared<const sph::ParticleSet>();
            s.particles.push_back(none);
            m.particles = none.get();
            m.withGhosts = nullptr;
            s.media.push_back(std::move(m));
            s.built.push_back(std::move(built));
        }
        return s;
    }

    std::string counts(const Simulation& sim) override
    {
        double liquid = 0, air = 0;
        for (const OutputMedium& m : sim.media()) {
            const auto& kinds = m.particles->kinds();
            const auto* halo = m.particles->hasScalarChannel(sph::HALO_CHANNEL)
                                   ? &m.particles->scalarChannel(sph::HALO_CHANNEL)
                                   : nullptr;
            for (std::size_t i = 0; i < kinds.size(); ++i) {
                if (halo && (*halo)[i] != sph::Real(0)) continue;
                liquid += kinds[i] == sph::ParticleKind::Liquid;
                air += kinds[i] == sph::ParticleKind::GhostAir;
            }
        }
        const double all = mExchange->sumOf(liquid + air);
        const double largest = mExchange->maxOf(liquid + air);
        return msg(
            std::size_t(mExchange->sumOf(liquid)), " liquid, ", std::size_t(mExchange->sumOf(air)),
            " air on ", ranks(), " processes (the largest part ",
            int(std::lround(100 * largest / std::max(1.0, all))), " %; ", mExchange->migrated(),
            " particles migrated and ", mExchange->rebalances(), " rebalances seen by this one",
            mPieceCounts.own + mPieceCounts.moved
                ? msg("; the last frame's pieces: ", mPieceCounts.copies,
                      " particles copied for the volumes, the largest piece from ",
                      mPieceCounts.largest, ", ", mPieceCounts.moved, " moved to their points leaf")
                : std::string(),
            ")");
    }

    bool any(bool yes) override { return mExchange->maxOf(yes ? 1.0 : 0.0) > 0; }
    double sumOf(double value) override { return mExchange->sumOf(value); }
    double maxOf(double value) override { return mExchange->maxOf(value); }

private:
    dist::MpiSession mSession;
    std::unique_ptr<dist::MpiExchange> mExchange;
    FramePieceCounts mPieceCounts;
};

} // namespace

std::unique_ptr<DistributedRun> DistributedRun::startIfLaunched()
{
    if (dist::launcherRankCount() <= 1) return nullptr;
    return std::make_unique<MpiRun>();
}

void abortDistributedRun(int code)
{
    if (gActive) MPI_Abort(MPI_COMM_WORLD, code);
}

void awaitDistributedAbort()
{
    if (gActive) MPI_Barrier(MPI_COMM_WORLD);
}

} // namespace cmd
} // namespace ghostfx
