/// @file   FrameWriter.cc
#include "FrameWriter.h"

namespace ghostfx {
namespace cmd {

FrameSnapshot snapshotFrame(const vdbio::SceneOutputs& outputs, const Simulation& sim, int frame)
{
    FrameSnapshot s;
    s.frame = frame;
    s.time = sim.time();
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
        writeFrameOutputs(mScene, snapshot, mFolder, &mPreviewCache);
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
        if (!failed) { // after a failure, later frames are dropped: the run is stopping
            try {
                writeFrameOutputs(mScene, snapshot, mFolder, &mPreviewCache);
            } catch (...) {
                error = std::current_exception();
            }
        }
        lock.lock();
        mWriting = false;
        if (error && !mError) mError = error;
        mChanged.notify_all();
    }
}

} // namespace cmd
} // namespace ghostfx
