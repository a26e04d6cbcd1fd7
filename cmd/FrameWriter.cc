/// @file   FrameWriter.cc
#include "FrameWriter.h"

#include <ghostfx/gas/GasChannels.h>
#include <ghostfx/sph/Exceptions.h>

#include <algorithm>

namespace ghostfx {
namespace cmd {

vdbio::PointsOptions pointsOptions(const OutputMedium& m, const vdbio::SceneOutputs& out,
                                   double time)
{
    vdbio::PointsOptions po;
    po.channels = m.liquid ? out.pointChannels : out.gasPointChannels;
    po.kinds = m.kinds;
    po.time = time;
    po.restDensity = m.restDensity;
    po.kernelSupport = m.support;
    if (out.pointGhosts && !m.ghostKinds.empty()) {
        po.kinds.insert(po.kinds.end(), m.ghostKinds.begin(), m.ghostKinds.end());
        if (std::find(po.channels.begin(), po.channels.end(), "kind") == po.channels.end()) {
            po.channels.push_back("kind");
        }
    }
    return po;
}

vdbio::VolumeOptions volumeOptions(const OutputMedium& m, const vdbio::SceneOutputs& out)
{
    const std::vector<std::string>& wanted = m.liquid ? out.volumeGrids : out.gasVolumeGrids;
    auto wants = [&](const char* g) {
        return std::find(wanted.begin(), wanted.end(), g) != wanted.end();
    };
    vdbio::VolumeOptions vo;
    // The liquid's surface at h / 2 by default; the gathered grids (the gas has no surface) at
    // h (VolumeOptions::densityVoxelSize says what that keeps).
    if (m.liquid) {
        vo.voxelSize = out.voxelSize > 0 ? out.voxelSize : 0.5 * m.spacing;
        vo.densityVoxelSize = out.densityVoxelSize;
    } else {
        vo.voxelSize = vo.densityVoxelSize = out.gasVoxelSize > 0 ? out.gasVoxelSize : m.spacing;
    }
    vo.kernelSupport = m.support;
    // A gas particle grown by the air it entrained spreads over its own support.
    if (!m.liquid && m.particles->hasScalarChannel(gas::channel::SUPPORT))
        vo.supportChannel = gas::channel::SUPPORT;
    vo.restDensity = m.restDensity;
    vo.particleSpacing = m.spacing;
    vo.kinds = m.kinds;
    vo.surface = m.liquid && wants("surface");
    vo.surfaceMethod = out.surfaceMethod;
    vo.density = wants("density");
    vo.velocity = wants("vel");
    if (wants("temperature")) {
        if (!m.particles->hasScalarChannel("temperature")) {
            throw SceneError(msg("outputs: grid 'temperature' asked for, but the ", m.name,
                                 " particles carry no temperature in this scene"));
        }
        vo.scalarChannels.push_back("temperature");
        vo.ambientTemperature = m.ambientTemperature;
    }
    if (!m.liquid && wants("smoke")) {
        if (!m.particles->hasScalarChannel("smoke")) {
            throw SceneError(msg("outputs.gas_volume.grids: grid 'smoke' asked for, but the gas "
                                 "carries no smoke share without entrainment (expected "
                                 "settings.gas.turbulence 'entrainment' or 'auto')"));
        }
        vo.scalarChannels.push_back("smoke");
    }
    return vo;
}

vdbio::VolumeOptions meshVolumeOptions(const OutputMedium& m, const vdbio::SceneOutputs& out)
{
    vdbio::VolumeOptions vo = volumeOptions(m, out);
    // The volume's own surface settings where its file is written (the scene reader holds the
    // mesh's to them), else the mesh section's.
    vo.surfaceMethod = out.meshSurfaceMethod;
    vo.voxelSize = out.meshVoxelSize > 0 ? out.meshVoxelSize : 0.5 * m.spacing;
    vo.surface = vo.velocity = true;
    vo.density = false;
    vo.scalarChannels.clear();
    return vo;
}

bool volumeHoldsMeshGrids(const vdbio::VolumeOptions& vo) { return vo.surface && vo.velocity; }

FrameSnapshot snapshotFrame(const vdbio::SceneOutputs& outputs, const Simulation& sim, int frame)
{
    FrameSnapshot s;
    s.frame = frame;
    s.time = sim.time();
    s.solidPlacements = sim.solidPlacements();
    for (OutputMedium m : sim.media()) {
        auto particles = std::make_shared<const sph::ParticleSet>(*m.particles);
        s.particles.push_back(particles);
        m.particles = particles.get();
        if (m.withGhosts) {
            if (outputs.pointGhosts && !outputs.pointsFile.empty()) {
                auto all = std::make_shared<const sph::ParticleSet>(m.withGhosts());
                s.particles.push_back(all);
                m.withGhosts = [all] { return *all; };
            } else {
                m.withGhosts = nullptr; // not written: nothing to copy
            }
        }
        s.media.push_back(std::move(m));
    }
    if (std::optional<vdbio::WhitewaterPoints> w = sim.whitewater())
        s.whitewater = std::make_shared<const vdbio::WhitewaterPoints>(std::move(*w));
    return s;
}

FrameWriter::FrameWriter(const vdbio::Scene& scene, std::string folder, bool overlap)
    : mScene(scene)
    , mFolder(std::move(folder))
{
    if (overlap) mThread = std::thread([this] { work(); });
}

FrameWriter::~FrameWriter()
{
    if (!mThread.joinable()) return;
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mStop = true;
    }
    mChanged.notify_all();
    mThread.join();
}

void FrameWriter::rethrow()
{
    if (mError) std::rethrow_exception(mError);
}

void FrameWriter::submit(FrameSnapshot snapshot)
{
    if (!mThread.joinable()) {
        std::vector<std::string> notes =
            writeFrameOutputs(mScene, snapshot, mFolder, &mPreviewCache);
        mNotes.insert(mNotes.end(), notes.begin(), notes.end());
        return;
    }
    std::unique_lock<std::mutex> lock(mMutex);
    mChanged.wait(lock, [this] { return !mQueued || mError; });
    rethrow();
    mQueued = std::move(snapshot);
    lock.unlock();
    mChanged.notify_all();
}

void FrameWriter::finish()
{
    if (!mThread.joinable()) return;
    std::unique_lock<std::mutex> lock(mMutex);
    mChanged.wait(lock, [this] { return (!mQueued && !mWriting) || mError; });
    rethrow();
}

std::vector<std::string> FrameWriter::takeNotes()
{
    std::lock_guard<std::mutex> lock(mMutex);
    std::vector<std::string> notes;
    notes.swap(mNotes);
    return notes;
}

void FrameWriter::work()
{
    std::unique_lock<std::mutex> lock(mMutex);
    for (;;) {
        mChanged.wait(lock, [this] { return mQueued || mStop; });
        if (!mQueued) return; // stopping, nothing left
        FrameSnapshot snapshot = std::move(*mQueued);
        mQueued.reset();
        mWriting = true;
        const bool failed = bool(mError);
        lock.unlock();
        mChanged.notify_all(); // the queue has room again
        std::exception_ptr error;
        std::vector<std::string> notes;
        if (!failed) { // after a failure, later frames are dropped: the run is stopping
            try {
                notes = writeFrameOutputs(mScene, snapshot, mFolder, &mPreviewCache);
            } catch (...) {
                error = std::current_exception();
            }
        }
        lock.lock();
        mNotes.insert(mNotes.end(), notes.begin(), notes.end());
        mWriting = false;
        if (error && !mError) mError = error;
        mChanged.notify_all();
    }
}

} // namespace cmd
} // namespace ghostfx
