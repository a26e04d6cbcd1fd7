/// @file   FrameWriter.h
/// @brief  Frame outputs written while the next frame simulates: a snapshot of the media is
///         taken after a frame (the particles copied, so the solver can step on) and a writer
///         thread builds and writes its files.
/// @details At most one snapshot waits while another is being written, so overlapping costs up
///          to two copies of the output particles (the points and volumes need nothing else).
///          Every file is still written atomically (AtomicFile.h), so a killed run leaves only
///          complete frames; finish() waits until every submitted frame is on disk, and the run
///          calls it before each checkpoint, so a checkpoint never gets ahead of the frames. A
///          write error is reported by the next submit() or finish().
#pragma once

#include "Simulation.h"

#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/ScenePreview.h>

#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace ghostfx {
namespace cmd {

/// A medium's points and volume grids built before they reach the writer: a run over several
/// processes merges them from every process's piece (DistributedRun::snapshot).
struct BuiltGrids
{
    openvdb::GridBase::Ptr points; ///< the "particles" PointDataGrid, or null: none written
    openvdb::GridPtrVec volumes;   ///< the volume file's grids (the preview draws them)
    /// The liquid's "surface" and "vel" grids the mesh output is made from (meshVolumeOptions)
    /// when the volume file does not hold both; empty otherwise.
    openvdb::GridPtrVec mesh;
};

/// What one frame's outputs need, owned: the media with copies of their particles, or their
/// grids already built.
struct FrameSnapshot
{
    int frame = 0;
    double time = 0; ///< s
    std::vector<OutputMedium> media;
    std::vector<std::shared_ptr<const sph::ParticleSet>> particles; ///< what `media` point to
    /// Per medium where its grids were built before the snapshot, else empty: the writer
    /// builds them from the particles.
    std::vector<BuiltGrids> built;
    /// Where each solid is at `time` (Simulation::solidPlacements), for the preview; empty:
    /// where the scene's motion puts it.
    std::vector<sph::RigidTransform> solidPlacements;
    /// The whitewater (Simulation::whitewater); null: the scene makes none.
    std::shared_ptr<const vdbio::WhitewaterPoints> whitewater;
};

/// The options a medium's points and volume outputs are built with, from the scene's outputs
/// (the liquid's surface at h / 2 unless the scene says otherwise, its gathered grids at h).
/// `time` (s): the state the points hold, for their "age".
vdbio::PointsOptions pointsOptions(const OutputMedium& m, const vdbio::SceneOutputs& out,
                                   double time);
vdbio::VolumeOptions volumeOptions(const OutputMedium& m, const vdbio::SceneOutputs& out);
/// The grids the liquid's mesh output is made from: the volume output's options with only
/// "surface" and "vel" asked for, the surface method and voxel size of outputs.mesh (the
/// volume's where its file is written: the same surface and velocity as the volume file's).
vdbio::VolumeOptions meshVolumeOptions(const OutputMedium& m, const vdbio::SceneOutputs& out);
/// Whether the volume grids `vo` already hold what the mesh output needs ("surface", "vel").
bool volumeHoldsMeshGrids(const vdbio::VolumeOptions& vo);

/// Copy what the scene's outputs of `frame` read from `sim` (with the ghosts only where the
/// points output asks for them).
FrameSnapshot snapshotFrame(const vdbio::SceneOutputs& outputs, const Simulation& sim, int frame);

/// Write the scene's outputs of a snapshot into `folder` (points, volume, mesh, whitewater and
/// preview files, as the scene's `outputs` name them); every file atomically. `previewCache` keeps the
/// static solids' preview hits from one frame to the next (the pictures are the same without
/// it). Returns lines for the run's log: what each mesh file holds.
std::vector<std::string> writeFrameOutputs(const vdbio::Scene& scene,
                                           const FrameSnapshot& snapshot,
                                           const std::string& folder,
                                           vdbio::PreviewCache* previewCache = nullptr);

class FrameWriter
{
public:
    /// `overlap` false: submit() writes at once, as a run without a writer thread would.
    FrameWriter(const vdbio::Scene& scene, std::string folder, bool overlap);
    /// Finishes the frames still queued (their errors are dropped: this runs while the run is
    /// already ending, normally after finish()).
    ~FrameWriter();
    FrameWriter(const FrameWriter&) = delete;
    FrameWriter& operator=(const FrameWriter&) = delete;

    /// Hand a frame over; waits while a frame is already queued. Throws a previous frame's
    /// write error.
    void submit(FrameSnapshot snapshot);
    /// Wait until every submitted frame is on disk; throws the first write error.
    void finish();
    /// The log lines of the frames written since the last call (writeFrameOutputs' lines), in
    /// frame order.
    std::vector<std::string> takeNotes();

private:
    void work();
    void rethrow();

    const vdbio::Scene& mScene;
    const std::string mFolder;
    vdbio::PreviewCache mPreviewCache; ///< used by whichever thread writes (one at a time)
    std::mutex mMutex;
    std::condition_variable mChanged;
    std::optional<FrameSnapshot> mQueued;
    bool mWriting = false, mStop = false;
    std::exception_ptr mError;
    std::vector<std::string> mNotes; ///< guarded by mMutex
    std::thread mThread;
};

} // namespace cmd
} // namespace ghostfx
