/// @file   GhostSolver.cc
/// @brief  [SB12] set-up: solids and their particle blocks, liquid bodies, emitters, the kill
///         box, the mass scaling, time stepping, and saving and restoring a run. The step is in
///         GhostStep.cc and DensityPass.cc, the air layer in GhostAir.cc, the pressure models
///         in TaitPressure.cc, DfsphPressure.cc and BasicPressure.cc.
#include "ghostfx/ghost/GhostSolver.h"

#include "GhostInternal.h"
#include "ImplicitViscosity.h"
#include "SurfaceTension.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/FrameSteps.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/ParticleAge.h>
#include <ghostfx/sph/PoissonSampler.h>
#include <ghostfx/sph/Random.h>
#include <ghostfx/sph/SphDensity.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

GhostSolver::GhostSolver(const GhostSettings& settings, std::unique_ptr<PressureSolver> pressure)
    : mSettings(settings)
    , mKernel((settings.validate(), settings.supportRadius()))
    , mGrid(settings.supportRadius())
    , mStatic(settings.supportRadius())
    , mMoving(settings.supportRadius())
    , mPressure(pressure ? std::move(pressure) : makePressureSolver(settings))
{
    // Model only what the scene needs: v* is used by every step of both methods, the ghost air
    // channels only by Ghost SPH (Basic SPH has no air). Solid channels live on the solid
    // particles only, in their blocks.
    mParticles.addVectorChannel(VSTAR);
    if (mSettings.method == Method::Ghost) {
        mParticles.addScalarChannel(AIR_WEIGHT, Real(1));
        mParticles.addScalarChannel(AIR_TARGET, Real(1));
    }
    for (const std::string& c : mPressure->channels()) mParticles.addScalarChannel(c);
    if (mSettings.viscosity > Real(0)) enableViscosity();
    if (mSettings.surfaceTension > Real(0)) {
        mSurfaceTension = std::make_unique<SurfaceTension>();
        mParticles.addScalarChannel(AIR_FADE, Real(1));
    }
    sph::ensureBirthTimes(mParticles, mRun.time);
}

GhostSolver::~GhostSolver() = default;

const PressureSolveStats& GhostSolver::pressureSolveStats() const
{
    static const PressureSolveStats none;
    const PressureSolveStats* stats = mPressure->solveStats();
    return stats ? *stats : none;
}

const ViscositySolveStats& GhostSolver::viscositySolveStats() const
{
    static const ViscositySolveStats none;
    return mViscosity ? mViscosity->stats() : none;
}

void GhostSolver::setParticleMass(Real mass)
{
    if (!(mass > Real(0)) || !std::isfinite(mass)) {
        throw ValueError(msg("particle mass = ", mass, " kg: expected a finite value > 0"));
    }
    mMass = mass;
    const std::vector<Real>* weight =
        mParticles.hasScalarChannel(AIR_WEIGHT) ? &mParticles.scalarChannel(AIR_WEIGHT) : nullptr;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        const bool air = weight && mParticles.kinds()[i] == ParticleKind::GhostAir;
        mParticles.masses()[i] = air ? (*weight)[i] * mass : mass;
    }
    for (SolidBlock* b : {&mStatic, &mMoving}) {
        auto& m = b->block.particles().masses();
        std::fill(m.begin(), m.end(), mass);
    }
}

void GhostSolver::setStepObserver(StepObserver observer) { mObserver = std::move(observer); }

void GhostSolver::setExchange(sph::ParticleExchange* exchange, bool ownPart)
{
    if (!exchange || exchange->ranks() == 1) {
        mExchange = nullptr;
        return;
    }
    auto refuse = [](const std::string& what) {
        throw ValueError(msg("liquid solver over several processes: ", what,
                             " is not supported yet (supported: method ghost, pressure tait or "
                             "dfsph)"));
    };
    if (mSettings.method != Method::Ghost) refuse("method basic");
    if (!mRun.initialized) refuse("sharing before prepare()");
    if (hasBodies()) refuse("a dynamic solid");
    if (mViscosity) refuse("viscosity");
    if (mSettings.surfaceTension > Real(0)) refuse("surface_tension");
    // A fresh run (or one restored whole): every process has the same particles here; keep
    // what this one owns. A run restored from this process's own part of a checkpoint keeps
    // all of it (the particles that left its region since the last exchange migrate at the
    // next one).
    if (!ownPart) {
        std::vector<std::uint8_t> remove(mParticles.size(), 0);
        for (std::size_t i = 0; i < remove.size(); ++i)
            remove[i] = !exchange->owns(mParticles.positions()[i]);
        mParticles.removeIf(remove);
    }
    mParticles.addScalarChannel(HALO_CHANNEL, Real(0));
    // New particles (air) take ids congruent to this rank modulo the rank count: the first
    // such id at or above every id any process holds now (the set-up was the same everywhere).
    // A state restored from this process's checkpoint already continues its sequence, and
    // keeps it.
    ParticleId next = mParticles.nextId();
    for (const SolidBlock* b : {&mStatic, &mMoving})
        next = std::max(next, b->block.particles().nextId());
    mExchange = exchange;
    continueIdsFrom(next);
}

void GhostSolver::continueIdsFrom(ParticleId next)
{
    if (!mExchange) {
        mParticles.setNextId(next);
        return;
    }
    // This rank's sequence: the ids congruent to its rank modulo the rank count.
    const ParticleId ranks = mExchange->ranks();
    next += ((mExchange->rank() - next % ranks) % ranks + ranks) % ranks;
    mParticles.setIdSequence(next, ranks);
}

// Solids ------------------------------------------------------------------------------------------

void GhostSolver::addSolid(const LevelSet& solid, const Vec3& velocity)
{
    if (!isFinite(velocity)) {
        throw ValueError(msg("solid '", solid.name(), "': velocity is not finite"));
    }
    addSolidBody(solid, sph::constantVelocity(velocity), velocity != Vec3(0));
}

void GhostSolver::addMovingSolid(const LevelSet& solid, RigidMotion motion)
{
    if (!motion) throw ValueError(msg("solid '", solid.name(), "': no motion given"));
    addSolidBody(solid, std::move(motion), true);
}

void GhostSolver::addSolidBody(const LevelSet& solid, RigidMotion motion, bool moving,
                               std::unique_ptr<Body> body)
{
    mSolids.push_back(
        std::make_unique<Solid>(Solid{{solid, std::move(motion)}, moving, std::move(body)}));
    // A solid the restored state already holds keeps its restored particles: sampling it again
    // would duplicate them (and, with a seed that depends on the step, differ from them).
    const std::size_t index = mSolids.size() - 1;
    if (index < mRestoredSolids) claimRestoredSolid(index);
    else sampleSolid(index);
    if (!mRun.initialized && !mRestored) clearLiquidFrom(index);
}

void GhostSolver::clearLiquidFrom(std::size_t solidIndex)
{
    // Liquid added before the solid and inside it (a script's solid over a scene's liquid) is
    // removed as addLiquid would have left it out (blockedBySolid's clearance): deeper than the
    // solid's band it could not be projected out, and the first steps stopped on it.
    const Solid& solid = *mSolids[solidIndex];
    const Real clearance = Real(0.5) * mSettings.spacing;
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    bool any = false;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::Liquid) continue;
        if (solid.phi(mParticles.positions()[i], mRun.time) < clearance) remove[i] = any = true;
    }
    if (any) mParticles.removeIf(remove);
}

GhostSolver::SolidBlock& GhostSolver::blockOf(std::size_t solidIndex)
{
    return mSolids[solidIndex]->moving ? mMoving : mStatic;
}

namespace {

/// Rest values (rest density, zero pressure, the solid's own velocity) in the particles
/// `touched` of a solid block's set.
void putRestValues(ParticleSet& set, const std::vector<Index>& touched, Real restDensity)
{
    const std::vector<Vec3>* solidV =
        set.hasVectorChannel(SOLID_VELOCITY) ? &set.vectorChannel(SOLID_VELOCITY) : nullptr;
    for (Index k : touched) {
        set.densities()[k] = restDensity;
        set.pressures()[k] = 0;
        set.velocities()[k] = solidV ? (*solidV)[k] : Vec3(0);
    }
}

} // namespace

void GhostSolver::restSolidValues(SolidBlock& b) const
{
    putRestValues(b.block.particles(), b.touched, mSettings.restDensity);
    b.touched.clear();
}

ParticleSet GhostSolver::restingParticles(const SolidBlock& b) const
{
    ParticleSet set = b.block.particles();
    putRestValues(set, b.touched, mSettings.restDensity);
    return set;
}

void GhostSolver::clearSolidScratch(SolidBlock& b)
{
    restSolidValues(b);
    b.nearest.clear();
    b.block.touch();
    mProjectAll = true;
}

void GhostSolver::setSolidShape(std::size_t solidIndex, const LevelSet& shape)
{
    if (solidIndex >= mSolids.size()) {
        throw ValueError(msg("setSolidShape: solid ", solidIndex, " does not exist (",
                             mSolids.size(), " solids)"));
    }
    if (mSolids[solidIndex]->body) {
        throw ValueError(
            msg("setSolidShape: solid '", mSolids[solidIndex]->shape.name(),
                "' is dynamic: its shape sets its mass and inertia, and cannot change"));
    }
    // Drop the old particles of this solid, then sample the new shape.
    restSolidValues(blockOf(solidIndex)); // its indices are about to change
    ParticleSet& set = blockOf(solidIndex).block.particles();
    const auto& index = set.scalarChannel(SOLID_INDEX);
    std::vector<std::uint8_t> remove(set.size(), 0);
    for (std::size_t i = 0; i < remove.size(); ++i) remove[i] = std::size_t(index[i]) == solidIndex;
    set.removeIf(remove);
    mSolids[solidIndex]->shape = shape;
    sampleSolid(solidIndex);
}

RigidTransform GhostSolver::solidPlacement(std::size_t solidIndex) const
{
    if (solidIndex >= mSolids.size()) {
        throw ValueError(msg("solidPlacement: solid ", solidIndex, " does not exist (",
                             mSolids.size(), " solids)"));
    }
    const Solid& solid = *mSolids[solidIndex];
    return solid.motion ? solid.at(time()) : RigidTransform();
}

void GhostSolver::setSolidMotion(std::size_t solidIndex, RigidMotion motion)
{
    if (solidIndex >= mSolids.size()) {
        throw ValueError(msg("setSolidMotion: solid ", solidIndex, " does not exist (",
                             mSolids.size(), " solids)"));
    }
    if (!motion) throw ValueError(msg("setSolidMotion: solid ", solidIndex, ": no motion given"));
    Solid& solid = *mSolids[solidIndex];
    if (solid.body) {
        throw ValueError(msg("solid '", solid.shape.name(),
                             "' is dynamic: the liquid and its contacts move it, not a motion"));
    }
    if (!solid.moving) {
        throw ValueError(
            msg("solid '", solid.shape.name(),
                "' was added as a static solid: its motion "
                "cannot change (give it a velocity or motion keys to make it a moving one)"));
    }
    solid.motion = std::move(motion);
}

PoissonSettings GhostSolver::bodySampling(std::uint64_t seed) const
{
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.tiledInterior = mSettings.tiledSampling;
    ps.volumeRelaxation = mSettings.samplingRelaxation;
    ps.seed = seed;
    return ps;
}

namespace {

/// The outward normal (in the solid's frame) of each sample of a solid's band, from its nearest
/// surface sample within 2 R: phi is clamped beyond the narrow band, which is often thinner
/// than a kernel radius. Zero where no surface sample is that near.
std::vector<Vec3> bandNormals(const SampleSet& samples, const LevelSet& solid, Real R)
{
    std::vector<Vec3> surface;
    std::vector<Vec3> surfaceNormal;
    for (std::size_t i = 0; i < samples.size(); ++i) {
        if (samples.onSurface[i]) {
            surface.push_back(samples.positions[i]);
            surfaceNormal.push_back(solid.normal(samples.positions[i]));
        }
    }
    NeighborGrid surfaceGrid(R);
    surfaceGrid.build(surface);
    std::vector<Vec3> normals(samples.size());
    for (std::size_t k = 0; k < samples.size(); ++k) {
        const Index s =
            surfaceGrid.nearest(samples.positions[k], Real(2) * R, [](Index) { return true; });
        normals[k] = s == INVALID_INDEX ? Vec3(0) : surfaceNormal[s];
    }
    return normals;
}

} // namespace

void GhostSolver::startSolidIds(ParticleSet& set)
{
    // Solid particles take their ids from the same counter as the liquid, so ids stay unique
    // across the sets. Over several processes every one samples the same solid: its particles
    // take the same ids everywhere, above every id any process has given.
    ParticleId firstId = std::max(set.nextId(), mParticles.nextId());
    if (mExchange) firstId = ParticleId(mExchange->maxOf(double(firstId)));
    set.setNextId(firstId);
}

LevelSet GhostSolver::ghostShapeOf(const Solid& solid) const
{
    // A dynamic solid's ghosts are sampled in the shape half a spacing inside its surface: the
    // liquid ends half a spacing beyond its particles' centres, so its boundary is then the
    // body's surface and the volume it displaces is the body's own (on a static solid's
    // surface layer it keeps half a spacing off). Sampled in the eroded shape, not moved in
    // from the surface: moving the samples of a 10 cm box in by 1 cm packed its ghosts 44 %
    // denser than the liquid, which held the liquid off it and floated a box of 500 kg/m^3
    // 1.5 cm high.
    if (!solid.body) return solid.shape;
    return erodedLevelSet(solid.shape, Real(0.5) * mSettings.spacing);
}

void GhostSolver::sampleSolid(std::size_t solidIndex)
{
    const Solid& body = *mSolids[solidIndex];
    const LevelSet& solid = body.shape;
    const RigidTransform xf = body.at(mRun.time);
    if (!isFinite(xf.translation)) {
        throw ValueError(msg("solid '", solid.name(),
                             "': motion gives a non-finite placement at t = ", mRun.time, " s"));
    }

    // [SB12] Sec. 4.4 / 4.5: ghost solid particles in a band one kernel radius deep, sampled
    // like liquid (surface, relaxation, interior, relaxation). Basic SPH uses the same layer as
    // its boundary particles.
    const LevelSet ghostShape = ghostShapeOf(body);
    PoissonSettings ps = bodySampling(mSettings.seed + 1000003ULL * (solidIndex + 1) + mRun.step);
    ps.bandDepth = mSettings.supportRadius();
    const SampleSet samples = sph::sampleVolumeStored(ps, ghostShape, mSampleStore);
    const std::vector<Vec3> localNormals =
        bandNormals(samples, ghostShape, mSettings.supportRadius());
    const std::vector<Vec3>& local = samples.positions;

    SolidBlock& target = blockOf(solidIndex);
    ParticleSet& set = target.block.particles();
    auto& normals = set.addVectorChannel(SOLID_NORMAL);
    auto& index = set.addScalarChannel(SOLID_INDEX, Real(-1));
    std::vector<Vec3>* localNormalChannel = nullptr;
    std::vector<Vec3>* locals = nullptr;
    std::vector<Vec3>* solidV = nullptr;
    if (body.moving) {
        localNormalChannel = &set.addVectorChannel(SOLID_LOCAL_NORMAL);
        locals = &set.addVectorChannel(SOLID_LOCAL);
        solidV = &set.addVectorChannel(SOLID_VELOCITY);
    }
    startSolidIds(set);
    std::vector<Vec3> positions(local);
    for (Vec3& x : positions) x = xf.toWorld(x);
    const ParticleKind kind =
        mSettings.method == Method::Ghost ? ParticleKind::GhostSolid : ParticleKind::Boundary;
    const Index first = set.addBatch(positions, mMass, kind);
    continueIdsFrom(set.nextId());
    for (std::size_t k = 0; k < samples.size(); ++k) {
        const Vec3& localNormal = localNormals[k];
        normals[first + k] = xf.rotation * localNormal;
        index[first + k] = Real(solidIndex);
        set.densities()[first + k] = mSettings.restDensity;
        if (body.moving) {
            (*localNormalChannel)[first + k] = localNormal;
            (*locals)[first + k] = local[k];
            (*solidV)[first + k] = body.velocity(local[k], mRun.time);
            set.velocities()[first + k] = (*solidV)[first + k];
        }
    }
    clearSolidScratch(target);
}

void GhostSolver::claimRestoredSolid(std::size_t solidIndex)
{
    // The restored solid particles of this solid move from the pending set into the block
    // their solid belongs to, with the values of a particle no liquid reaches.
    const auto& index = mPendingSolids.scalarChannel(SOLID_INDEX);
    std::vector<std::uint8_t> mine(mPendingSolids.size(), 0);
    for (std::size_t i = 0; i < mine.size(); ++i) mine[i] = std::size_t(index[i]) == solidIndex;
    ParticleSet claimed = mPendingSolids.select(mine);
    mPendingSolids.removeIf(mine);
    const bool moving = mSolids[solidIndex]->moving;
    if (!moving) {
        for (const char* c : {SOLID_VELOCITY, SOLID_LOCAL, SOLID_LOCAL_NORMAL})
            claimed.removeChannel(c);
    } else {
        for (const char* c : {SOLID_VELOCITY, SOLID_LOCAL, SOLID_LOCAL_NORMAL}) {
            if (!claimed.hasVectorChannel(c)) {
                throw ValueError(msg("restoreState: moving solid ", solidIndex, " has no '", c,
                                     "' channel in the state (was it saved as a static solid?)"));
            }
        }
    }
    for (std::size_t i = 0; i < claimed.size(); ++i) {
        claimed.densities()[i] = mSettings.restDensity;
        claimed.pressures()[i] = 0;
        claimed.velocities()[i] = moving ? claimed.vectorChannel(SOLID_VELOCITY)[i] : Vec3(0);
    }
    SolidBlock& target = blockOf(solidIndex);
    target.block.particles().append(claimed);
    clearSolidScratch(target);
}

void GhostSolver::moveSolids(double time)
{
    // Solids move rigidly: every particle of a moving solid goes to its material point's new
    // place and velocity. Static solids are never touched.
    mMaxSolidSpeed = 0;
    ParticleSet& set = mMoving.block.particles();
    if (set.empty()) return;
    const std::vector<RigidTransform> placement = sph::placementsAt(mSolids, time);
    auto& x = set.positions();
    auto& v = set.velocities();
    const auto& local = set.vectorChannel(SOLID_LOCAL);
    const auto& localNormal = set.vectorChannel(SOLID_LOCAL_NORMAL);
    const auto& index = set.scalarChannel(SOLID_INDEX);
    auto& normal = set.vectorChannel(SOLID_NORMAL);
    auto& solidV = set.vectorChannel(SOLID_VELOCITY);
    std::vector<Real> speed(set.size());
    parallel::forEach(0, set.size(), [&](std::size_t i) {
        const std::size_t b = std::size_t(index[i]);
        x[i] = placement[b].toWorld(local[i]);
        normal[i] = placement[b].rotation * localNormal[i];
        solidV[i] = mSolids[b]->velocity(local[i], time);
        v[i] = solidV[i];
        speed[i] = solidV[i].length();
    });
    mMaxSolidSpeed = speed.empty() ? Real(0) : *std::max_element(speed.begin(), speed.end());
    // Re-sorted at the start of the next step (after its scratch is reset).
    mMoving.block.touch();
}

void GhostSolver::appendSolidPositionsInBox(const Aabb& box, std::vector<Vec3>& out) const
{
    for (const SolidBlock* b : {&mStatic, &mMoving}) {
        if (b->block.empty()) continue;
        if (b->block.stale()) {
            // Not yet sorted (added since the last step): test every particle.
            for (const Vec3& x : b->block.particles().positions()) {
                if (box.contains(x)) out.push_back(x);
            }
        } else {
            b->block.grid().forEachInBox(box, [&](Index, const Vec3& x) { out.push_back(x); });
        }
    }
}

// Liquid and emitters ----------------------------------------------------------------------------

std::size_t GhostSolver::addLiquid(const LevelSet& shape, const Vec3& velocity,
                                   std::optional<Real> viscosity)
{
    if (mRestored) {
        throw ValueError(msg("liquid '", shape.name(),
                             "': cannot add liquid after restoreState(); "
                             "the restored particles already hold the liquid (skip liquid "
                             "bodies when resuming)"));
    }
    const std::string what = msg("liquid '", shape.name(), "'");
    if (viscosity) checkOwnViscosity(*viscosity, what); // before anything is added
    const PoissonSettings ps =
        bodySampling(mSettings.seed + 7919ULL * (mParticles.count(ParticleKind::Liquid) + 1));
    const SampleSet samples = sph::sampleVolumeStored(ps, shape, mSampleStore);
    // Liquid inside a solid is not liquid, and liquid samples on a surface shared with a solid
    // would sit on top of the solid's own surface samples: keep half a spacing of clearance.
    std::vector<Vec3> kept;
    kept.reserve(samples.size());
    for (const Vec3& x : samples.positions) {
        if (!blockedBySolid(x)) kept.push_back(x);
    }
    const Index first = Index(mParticles.size());
    addLiquidParticles(kept, velocity);
    if (viscosity) giveViscosity(first, *viscosity, what);
    return kept.size();
}

void GhostSolver::addLiquidParticles(const std::vector<Vec3>& positions, const Vec3& velocity,
                                     std::optional<Real> viscosity)
{
    if (mRestored) {
        throw ValueError("cannot add liquid particles after restoreState(); the restored particles "
                         "already hold the liquid (skip liquid bodies when resuming)");
    }
    if (viscosity) checkOwnViscosity(*viscosity, "liquid particles");
    for (std::size_t k = 0; k < positions.size(); ++k) {
        if (!isFinite(positions[k])) {
            throw ValueError(msg("liquid particle ", k, " has a non-finite position"));
        }
    }
    const Index first = mParticles.addBatch(positions, mMass, ParticleKind::Liquid);
    std::fill(mParticles.velocities().begin() + first, mParticles.velocities().end(), velocity);
    if (viscosity) giveViscosity(first, *viscosity, "liquid particles");
}

void GhostSolver::giveViscosity(Index first, Real nu, const std::string& what)
{
    checkOwnViscosity(nu, what);
    std::vector<Real>& channel =
        mParticles.addScalarChannel(ImplicitViscosity::NU_CHANNEL, mSettings.viscosity);
    std::fill(channel.begin() + first, channel.end(), nu);
    if (nu > Real(0)) enableViscosity();
}

void GhostSolver::enableViscosity()
{
    if (!mViscosity) mViscosity = std::make_unique<ImplicitViscosity>();
    mParticles.addVectorChannel(ImplicitViscosity::CHANNEL);
}

bool GhostSolver::blockedBySolid(const Vec3& x) const
{
    // Liquid keeps half a spacing from solid surfaces, where the solid's own surface samples sit.
    const Real clearance = Real(0.5) * mSettings.spacing;
    for (const auto& solid : mSolids) {
        if (solid->phi(x, mRun.time) < clearance) return true;
    }
    return false;
}

void GhostSolver::addEmitter(const LevelSet& shape, const Vec3& velocity, double startTime,
                             double endTime, std::optional<Real> viscosity)
{
    if (!isFinite(velocity)) {
        throw ValueError(msg("emitter '", shape.name(), "': velocity is not finite"));
    }
    if (!(endTime > startTime) || !(startTime >= 0)) {
        throw ValueError(msg("emitter '", shape.name(), "': start ", startTime, " s, end ", endTime,
                             " s: expected 0 <= start < end"));
    }
    auto emitter = std::make_unique<Emitter>(shape, velocity, startTime, endTime);
    emitter->viscosity = viscosity;
    // The channel and the solve exist from now on, so a checkpoint made before the emitter
    // starts holds them.
    if (viscosity) giveViscosity(Index(mParticles.size()), *viscosity, msg("emitter '", shape.name(), "'"));
    if (velocity.lengthSqr() > Real(0)) {
        // Half the finer of the spacing and the voxel, but at most 512 cells across the shape
        // (a metre-wide emitter at 5 mm would otherwise trace 640k rays): the outline's cells
        // count in part, so a coarser grid loses little (LevelSet::shadowArea).
        const Vec3 extent = shape.bounds().extent();
        const Real resolution = std::max(Real(0.5) * std::min(mSettings.spacing, shape.voxelSize()),
                                         std::max({extent[0], extent[1], extent[2]}) / Real(512));
        emitter->crossSection = shape.shadowArea(velocity, resolution);
    }
    if (mEmitters.size() < mRestoredEmitterFills.size()) {
        std::tie(emitter->credit, emitter->fillScale) = mRestoredEmitterFills[mEmitters.size()];
    }
    mEmitters.push_back(std::move(emitter));
}

void GhostSolver::addMovingEmitter(const LevelSet& shape, const Vec3& velocity, RigidMotion motion,
                                   double startTime, double endTime,
                                   std::optional<Real> viscosity)
{
    if (!motion) throw ValueError(msg("moving emitter '", shape.name(), "': no motion given"));
    addEmitter(shape, velocity, startTime, endTime, viscosity);
    mEmitters.back()->motion = std::move(motion);
    mEmitters.back()->placeAt(mRun.time);
}

std::vector<GhostSolver::EmitterRate> GhostSolver::emitterRates() const
{
    std::vector<EmitterRate> rates;
    for (const auto& em : mEmitters) {
        rates.push_back({em->crossSection, double(mSettings.restDensity)
                                               * double(em->velocity.length()) * em->crossSection});
    }
    return rates;
}

void GhostSolver::accrueEmission(double t0, double t1)
{
    const std::vector<EmitterRate> rates = emitterRates();
    for (std::size_t e = 0; e < mEmitters.size(); ++e) {
        const Emitter& em = *mEmitters[e];
        const double active = std::min(t1, em.end) - std::max(t0, em.start);
        if (active > 0) mEmitters[e]->credit += rates[e].massRate * active;
    }
}

void GhostSolver::emit()
{
    for (std::size_t e = 0; e < mEmitters.size(); ++e) {
        Emitter& em = *mEmitters[e];
        em.placeAt(mRun.time);
        if (mRun.time >= em.start && mRun.time < em.end) emitFrom(e);
    }
}

void GhostSolver::emitFrom(std::size_t e)
{
    Emitter& em = *mEmitters[e];
    const Real R = mSettings.supportRadius();
    const Aabb& box = em.box;
    const Aabb near = box.padded(R);

    // Air inside the emitter gives way to the liquid at once.
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    bool anyAir = false;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] == ParticleKind::GhostAir
            && em.placedPhi(mParticles.positions()[i]) < Real(0)) {
            remove[i] = anyAir = true;
        }
    }
    if (anyAir) mParticles.removeIf(remove);

    // Seeds: liquid already in the emitter; obstacles: every other particle nearby. The
    // liquid inside moves at the emitter's velocity (the emitter is kept full of liquid
    // moving so): left at its own, gravity and the pressure of the fills sped it up inside
    // the nozzle and a tap poured 30 % (DFSPH) to 120 % (Tait at CFL 0.2) over its rate,
    // more the smaller the steps (bench/history/diary-2026-11.md, "The tap's rate by mass").
    std::vector<Vec3> seeds, obstacles;
    auto& v = mParticles.velocities();
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        const Vec3& x = mParticles.positions()[i];
        if (!near.contains(x)) continue;
        if (mParticles.kinds()[i] == ParticleKind::Liquid && em.placedPhi(x) < Real(0)) {
            seeds.push_back(x);
            v[i] = em.liquidVelocity(x);
        } else {
            obstacles.push_back(x);
        }
    }
    // Over several processes, every one sees the emitter's surroundings whole (so all
    // sample the same new liquid) and keeps the new particles in its own region.
    if (mExchange) {
        seeds = mExchange->allPositions(seeds);
        obstacles = mExchange->allPositions(obstacles);
    }
    appendSolidPositionsInBox(near, obstacles);
    std::vector<Vec3> fresh = emitterFill(e, seeds, obstacles, box);
    if (seeds.empty()) em.credit = 0;
    else limitToCredit(em, e, fresh);
    if (mExchange) {
        fresh.erase(std::remove_if(fresh.begin(), fresh.end(),
                                   [&](const Vec3& x) { return !mExchange->owns(x); }),
                    fresh.end());
    }
    if (fresh.empty()) return;
    const Index first = mParticles.addBatch(fresh, mMass, ParticleKind::Liquid);
    em.giveVelocities(fresh, mParticles.velocities().data() + first);
    if (em.viscosity) {
        std::vector<Real>& nu = mParticles.scalarChannel(ImplicitViscosity::NU_CHANNEL);
        std::fill(nu.begin() + first, nu.end(), *em.viscosity);
    }
    mRun.emitted += fresh.size();
}

std::vector<Vec3> GhostSolver::emitterFill(std::size_t e, const std::vector<Vec3>& seeds,
                                           const std::vector<Vec3>& obstacles,
                                           const Aabb& box) const
{
    const Emitter& em = *mEmitters[e];
    std::vector<Vec3> fresh;
    if (seeds.empty()) {
        // Nothing to grow from: fill the emitter as an initial liquid body ([SB12] Sec. 4.5).
        const PoissonSettings ps = bodySampling(mSettings.seed + 31337ULL * (e + 1) + mRun.step);
        for (const Vec3& local : PoissonDiskSampler(ps).sampleVolume(em.shape).positions) {
            const Vec3 x = em.placedPoint(local);
            bool clear = !blockedBySolid(x);
            for (const Vec3& o : obstacles) {
                if (!clear) break;
                clear = (o - x).lengthSqr() >= sqr(ps.radius);
            }
            if (clear) fresh.push_back(x);
        }
    } else {
        PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
        ps.volumeAttempts = PoissonSettings::SB12_SEEDED_ATTEMPTS;
        ps.radius *= Real(em.fillScale);
        ps.seed = mSettings.seed ^ (0xc2b2ae3d27d4eb4fULL * (mRun.step + 1) + e);
        auto accept = [&](const Vec3& x) {
            return em.placedPhi(x) < Real(0) && !blockedBySolid(x);
        };
        fresh = PoissonDiskSampler(ps).sampleFromSeeds(seeds, obstacles, accept, box);
    }
    return fresh;
}

namespace {

/// How the emitter's fill radius adapts (GhostSolver::limitToCredit): a factor a step, and
/// at most this many Poisson radii.
constexpr double FILL_SCALE_STEP = 1.01, MAX_FILL_SCALE = 1.15;

} // namespace

void GhostSolver::limitToCredit(Emitter& em, std::size_t e, std::vector<Vec3>& fresh) const
{
    // The fills find every gap of r in the nozzle, and gaps opened a few millimetres a step
    // fill more tightly than the sampler's relaxed bodies: a tap held at its velocity poured
    // 10-17 % over rho0 v A with either pressure model (bench/history/diary-2026-11.md, "The tap's
    // rate by mass"). The fills are capped by the mass the emitter owes; a random choice of them
    // (the same on every process: all sample the same fills) spreads the gaps left evenly,
    // and the next steps' fills find them again.
    if (em.crossSection <= 0 || mMass <= Real(0)) return;
    const double mass = double(mMass);
    const std::size_t owed = std::size_t(std::max(0.0, std::floor(em.credit / mass)));
    const bool capped = fresh.size() > owed;
    if (capped) {
        sph::Rng rng(mSettings.seed ^ (0x9e3779b97f4a7c15ULL * (mRun.step + 1)), 2 * e + 1);
        std::vector<std::uint32_t> order(fresh.size());
        for (std::size_t k = 0; k < order.size(); ++k) order[k] = std::uint32_t(k);
        for (std::size_t k = 0; k < owed; ++k) {
            std::swap(order[k], order[k + rng.below(std::uint32_t(order.size() - k))]);
        }
        order.resize(owed);
        std::sort(order.begin(), order.end());
        std::vector<Vec3> kept(owed);
        for (std::size_t k = 0; k < owed; ++k) kept[k] = fresh[order[k]];
        fresh.swap(kept);
    }
    em.credit -= double(fresh.size()) * mass;
    // Thinned fills leave the nozzle's top short of liquid, so the fills' radius follows the
    // packing that pays the rate: a little wider while the fills outrun the credit, back
    // towards r while they fall a layer behind (a 5 mm tap under gravity settles near 1.06 r,
    // bench/history/diary-2026-11.md, "An emitter that pours its rate").
    const double layer =
        double(mSettings.restDensity) * em.crossSection * double(mSettings.spacing);
    if (capped) em.fillScale = std::min(MAX_FILL_SCALE, em.fillScale * FILL_SCALE_STEP);
    else if (em.credit > layer) em.fillScale = std::max(1.0, em.fillScale / FILL_SCALE_STEP);
    // An emitter that cannot fill (liquid backed up, a solid in the way) owes no more than
    // two layers, so it does not burst when freed.
    em.credit = std::min(em.credit, 2 * layer);
}

void GhostSolver::applyKillBox()
{
    const Aabb& box = mSettings.killBox;
    if (box.empty()) return;
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    std::size_t killed = 0;
    bool any = false;
    // Ghost air is not removed: it completes the neighbourhoods of the liquid still inside,
    // and the resampling keeps it within a layer of the liquid. Cut at the box, it left the
    // last particles of a liquid pouring out with half a neighbourhood, and they were flung
    // back up into the box.
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        const ParticleKind kind = mParticles.kinds()[i];
        if (kind != ParticleKind::GhostAir && !box.contains(mParticles.positions()[i])) {
            remove[i] = any = true;
            killed += kind == ParticleKind::Liquid;
        }
    }
    if (any) mParticles.removeIf(remove);
    mRun.killed += killed;
}

// Initialisation: the first air layer and the mass scaling ---------------------------------------

bool GhostSolver::initialize()
{
    if (mRun.initialized) return true;
    if (mParticles.count(ParticleKind::Liquid) == 0) emit();
    if (mParticles.count(ParticleKind::Liquid) == 0) {
        // Nothing to simulate yet, but an emitter starts later: wait for it (the mass scaling
        // and the first air layer are made from its first liquid).
        for (const auto& em : mEmitters) {
            if (em->end > mRun.time && em->start < std::numeric_limits<double>::infinity())
                return false;
        }
        throw ValueError("liquid solver: no liquid particles (add a liquid body, particles, or an "
                         "emitter that is active now or starts later)");
    }
    if (mSettings.method == Method::Ghost) {
        prepareSolidBlocks();
        searchNeighbors();
        resampleAir(-1);
    }

    if (mMass == Real(0)) scaleMass();
    else setParticleMass(mMass);
    if (mSettings.method == Method::Ghost && !mRestored) relaxInitialLiquid();
    if (mSettings.method == Method::Basic) mLennardJones = basicLennardJones();
    mRun.initialized = true;
    return true;
}

void GhostSolver::scaleMass()
{
    // [SB12] Sec. 4.6: scale the mass so the liquid's mean density is rho0, measured with a
    // ghost air layer in place so every liquid particle has a complete neighbourhood. Basic
    // SPH gets the same mass (its air layer is sampled for the measurement only, massProbe),
    // so the two methods start from the same state and differ only in how they treat the
    // surface.
    std::unique_ptr<GhostSolver> probe;
    if (mSettings.method == Method::Basic) probe = massProbe();
    setParticleMass(restDensityMass(probe ? *probe : *this));
}

Real GhostSolver::restDensityMass(const GhostSolver& measured) const
{
    const ParticleSet all = measured.allParticles();
    std::vector<std::uint8_t> liquid(all.size());
    for (std::size_t i = 0; i < liquid.size(); ++i)
        liquid[i] = all.kinds()[i] == ParticleKind::Liquid;
    return massForRestDensity(all.positions(), mKernel, mSettings.restDensity, liquid);
}

Real GhostSolver::startParticleMass() const
{
    if (mRun.initialized || mMass != Real(0)) return mMass;
    if (mParticles.count(ParticleKind::Liquid) == 0) return Real(0);
    return restDensityMass(*massProbe());
}

std::unique_ptr<GhostSolver> GhostSolver::massProbe() const
{
    GhostSettings probeSettings = mSettings;
    probeSettings.method = Method::Ghost;
    auto probe = std::make_unique<GhostSolver>(probeSettings);
    // The probe shares the solids and takes this solver's boundary particles as its ghost
    // solids: sampling them again would cost as much as the first time.
    // (A dynamic solid's copy keeps its placement through the motion and owns no body.)
    for (const auto& solid : mSolids) {
        probe->mSolids.push_back(
            std::make_unique<Solid>(Solid{{solid->shape, solid->motion}, solid->moving, nullptr}));
    }
    for (const SolidBlock* b : {&mStatic, &mMoving}) {
        SolidBlock& to = b == &mStatic ? probe->mStatic : probe->mMoving;
        to.block.particles() = restingParticles(*b);
        auto& kinds = to.block.particles().kinds();
        std::fill(kinds.begin(), kinds.end(), ParticleKind::GhostSolid);
        to.block.touch();
    }
    std::vector<Vec3> liquidOnly;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] == ParticleKind::Liquid)
            liquidOnly.push_back(mParticles.positions()[i]);
    }
    probe->addLiquidParticles(liquidOnly);
    probe->prepareSolidBlocks();
    probe->searchNeighbors();
    probe->resampleAir(-1);
    return probe;
}

Real GhostSolver::basicLennardJones() const
{
    if (mSettings.lennardJonesStrength != Real(0)) return mSettings.lennardJonesStrength;
    // Monaghan 1994: D of the order of the largest squared speed, 5 g H.
    const Real g = mSettings.gravity.length();
    Real lo = std::numeric_limits<Real>::max(), hi = -lo;
    const Vec3 up = g > Real(0) ? -mSettings.gravity / g : Vec3(0, 1, 0);
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::Liquid) continue;
        const Real h = mParticles.positions()[i].dot(up);
        lo = std::min(lo, h);
        hi = std::max(hi, h);
    }
    return g > Real(0) ? Real(5) * g * std::max(hi - lo, mSettings.spacing)
                       : sqr(Real(0.1) * mSettings.soundSpeed());
}

// Counts and views ------------------------------------------------------------------------------

std::size_t GhostSolver::count(ParticleKind kind) const
{
    return mParticles.count(kind) + mStatic.block.particles().count(kind)
           + mMoving.block.particles().count(kind) + mPendingSolids.count(kind);
}

ParticleSet GhostSolver::solidParticles() const
{
    ParticleSet out;
    for (const SolidBlock* b : {&mStatic, &mMoving}) {
        // The last step's extrapolation where liquid reached ([SB12] Algorithm 3), rest values
        // elsewhere: the block keeps both in its channels.
        out.append(b->block.particles());
    }
    out.append(mPendingSolids);
    return out;
}

std::size_t GhostSolver::neighborListBytes() const
{
    return mFluidLists.memoryBytes() + mStatic.lists.memoryBytes() + mMoving.lists.memoryBytes();
}

ParticleSet GhostSolver::allParticles() const
{
    ParticleSet out = mParticles;
    out.append(solidParticles());
    return out;
}

GhostSolver::MemoryUse GhostSolver::memoryUse() const
{
    MemoryUse use;
    use.particles = mParticles.memoryBytes();
    use.grid = mGrid.memoryBytes();
    use.lists = mFluidLists.memoryBytes();
    use.solidParticles = mPendingSolids.memoryBytes();
    use.stepArrays =
        mQueryMask.capacity() + mScratch.capacity() * sizeof(Real) + mPressure->memoryBytes();
    for (const SolidBlock* b : {&mStatic, &mMoving}) {
        use.solidParticles += b->block.particles().memoryBytes();
        use.solidGrids += b->block.grid().memoryBytes();
        use.solidLists += b->lists.memoryBytes();
        use.stepArrays += b->nearest.memoryBytes() + b->touched.capacity() * sizeof(Index);
    }
    return use;
}

// Save and restore ----------------------------------------------------------------------------------

SolverState GhostSolver::saveState() const
{
    SolverState state;
    state.solver = methodName(mSettings.method);
    // The solid particles as the blocks hold them (the step's extrapolation is scratch).
    state.particles = mParticles;
    for (const SolidBlock* b : {&mStatic, &mMoving}) state.particles.append(restingParticles(*b));
    state.particles.append(mPendingSolids);
    mRun.save(state);
    state.reals["particle_mass"] = double(mMass);
    state.reals["lennard_jones"] = double(mLennardJones);
    state.integers["solids"] = std::int64_t(mSolids.size());
    state.integers["emitters"] = std::int64_t(mEmitters.size());
    state.integers["pressure_dfsph"] = mSettings.pressure == PressureModel::Dfsph;
    state.integers["air_weights_complete"] = mSettings.airWeights == AirWeights::Complete;
    state.integers["air_phase"] = std::int64_t(mAirPhase);
    state.reals["air_phase_credit"] = mAirPhaseCredit;
    for (std::size_t e = 0; e < mEmitters.size(); ++e) {
        state.reals["emitter_credit_" + std::to_string(e)] = mEmitters[e]->credit;
        state.reals["emitter_fill_scale_" + std::to_string(e)] = mEmitters[e]->fillScale;
    }
    saveBodies(state);
    return state;
}

void GhostSolver::checkStateFits(const SolverState& state) const
{
    const std::string method = methodName(mSettings.method);
    if (state.solver != method) {
        throw ValueError(msg("restoreState: the state was saved by the '", state.solver,
                             "' solver, this solver runs '", method,
                             "'; resume with the method "
                             "the run started with"));
    }
    if (mRestored || mRun.initialized || mRun.step != 0 || !mParticles.empty() || !mSolids.empty()
        || !mEmitters.empty()) {
        throw ValueError("restoreState: call it on a freshly constructed solver, before adding "
                         "solids, emitters or liquid and before the first step");
    }
    const PressureModel saved =
        state.integer("pressure_dfsph", 0, 1) != 0 ? PressureModel::Dfsph : PressureModel::Tait;
    if (saved != mSettings.pressure) {
        throw ValueError(msg("restoreState: the state was saved with settings.pressure = '",
                             pressureName(saved), "', this run has '",
                             pressureName(mSettings.pressure),
                             "'; resume with the pressure model the run started with"));
    }
    const bool savedComplete = state.integer("air_weights_complete", 0, 1) != 0;
    if (savedComplete != (mSettings.airWeights == AirWeights::Complete)) {
        const char* saved = savedComplete ? "complete" : "matched";
        throw ValueError(msg("restoreState: the state was saved with ", saved,
                             " air weights (GhostSettings::airWeights), this solver has ",
                             savedComplete ? "matched" : "complete",
                             "; resume with the weights the run started with"));
    }
}

std::vector<std::uint8_t> GhostSolver::solidParticlesOf(const SolverState& state,
                                                        std::int64_t solids)
{
    // Every solid particle must name a solid the caller will add again.
    const ParticleSet& p = state.particles;
    const std::vector<Real>* index =
        p.hasScalarChannel(SOLID_INDEX) ? &p.scalarChannel(SOLID_INDEX) : nullptr;
    std::vector<std::uint8_t> solid(p.size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        const ParticleKind k = p.kinds()[i];
        if (k != ParticleKind::GhostSolid && k != ParticleKind::Boundary) continue;
        if (!index || !((*index)[i] >= Real(0)) || (*index)[i] >= Real(solids)) {
            throw ValueError(msg("restoreState: ", kindName(k), " particle id ", p.ids()[i],
                                 " belongs to no solid of the state (", solids, " solids)"));
        }
        solid[i] = 1;
    }
    return solid;
}

void GhostSolver::restoreState(const SolverState& state)
{
    checkStateFits(state);
    // Read every key first, so a state missing one leaves the solver untouched.
    const sph::RunCounters run = sph::RunCounters::load(state);
    const double mass = state.real("particle_mass");
    const double lennardJones = state.real("lennard_jones");
    const std::int64_t solids = state.count("solids"), emitters = state.count("emitters");
    const std::uint64_t airPhase = std::uint64_t(state.count("air_phase"));
    const double airPhaseCredit = state.real("air_phase_credit");
    std::vector<std::pair<double, double>> emitterFills; // credit (kg) and fill scale
    for (std::int64_t e = 0; e < emitters; ++e) {
        emitterFills.emplace_back(state.real("emitter_credit_" + std::to_string(e)),
                                  state.real("emitter_fill_scale_" + std::to_string(e)));
    }

    readRestoredBodies(state);
    const ParticleSet& p = state.particles;
    const std::vector<std::uint8_t> solid = solidParticlesOf(state, solids);
    if (mSettings.method == Method::Basic && p.count(ParticleKind::GhostAir) > 0) {
        throw ValueError("restoreState: a 'basic' state holds ghost air particles");
    }

    // Liquid and air go to the particle set; the solid particles wait for their solid to be
    // added again, which tells whether it is static or moving.
    std::vector<std::uint8_t> moving(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) moving[i] = !solid[i];
    mParticles = p.select(moving);
    mPendingSolids = p.select(solid);
    for (const char* c :
         {SOLID_NORMAL, SOLID_INDEX, SOLID_VELOCITY, SOLID_LOCAL, SOLID_LOCAL_NORMAL}) {
        mParticles.removeChannel(c);
    }
    for (const char* c : {VSTAR, AIR_WEIGHT, AIR_TARGET, sph::BIRTH_TIME_CHANNEL})
        mPendingSolids.removeChannel(c);
    // States saved by this solver have these channels; a missing one gets what a fresh solver
    // would have.
    mParticles.addVectorChannel(VSTAR);
    if (mSettings.method == Method::Ghost) {
        mParticles.addScalarChannel(AIR_WEIGHT, Real(1));
        mParticles.addScalarChannel(AIR_TARGET, Real(1));
    }
    for (const std::string& c : mPressure->channels()) mParticles.addScalarChannel(c);
    // A state whose liquids had their own viscosities keeps them (and its solve).
    if (mParticles.hasScalarChannel(ImplicitViscosity::NU_CHANNEL)) enableViscosity();
    if (mViscosity) mParticles.addVectorChannel(ImplicitViscosity::CHANNEL);
    if (mSurfaceTension) mParticles.addScalarChannel(AIR_FADE, Real(1));
    mRun = run;
    sph::ensureBirthTimes(mParticles, mRun.time);
    mAirPhase = airPhase;
    mAirPhaseCredit = airPhaseCredit;
    mRestoredEmitterFills = emitterFills;
    mMass = Real(mass);
    mLennardJones = Real(lennardJones);
    mRestoredSolids = std::size_t(solids);
    mRestoredEmitters = std::size_t(emitters);
    mRestored = true;
}

void GhostSolver::checkRestoredInputs() const
{
    if (mSolids.size() < mRestoredSolids) {
        throw ValueError(msg("liquid solver: the restored state has ", mRestoredSolids,
                             " solids but ", mSolids.size(),
                             " were added after restoreState(); "
                             "add the same solids, in the same order, before stepping"));
    }
    if (mEmitters.size() < mRestoredEmitters) {
        throw ValueError(msg("liquid solver: the restored state has ", mRestoredEmitters,
                             " emitters but ", mEmitters.size(),
                             " were added after "
                             "restoreState(); add the same emitters, in the same order, before "
                             "stepping"));
    }
}

// Time stepping ----------------------------------------------------------------------------------

Real GhostSolver::stableTimeStep() const
{
    // Acoustic CFL: dt <= cfl h / (c + |v|max); body force: dt <= cfl sqrt(h / |g|).
    const auto& v = mParticles.velocities();
    Real vmax = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (mParticles.kinds()[i] == ParticleKind::Liquid) vmax = std::max(vmax, v[i].length());
    }
    // Every process takes the same step: the fastest liquid of them all (between steps a
    // process holds no halo copies).
    if (mExchange) vmax = Real(mExchange->maxOf(double(vmax)));
    // A dynamic solid's fastest point moves no farther in a step than the liquid may.
    if (hasBodies()) vmax = std::max(vmax, fastestBody());
    const Real dt = mPressure->stableTimeStep(mSettings, vmax, mRun.maxAcceleration);
    return mSurfaceTension ? std::min(dt, SurfaceTension::capillaryTimeStep(mSettings)) : dt;
}

void GhostSolver::advanceFrame()
{
    checkRestoredInputs();
    initialize();
    // A DFSPH step that does not end the frame leaves the pressure channel as it was (only
    // output reads it). The last step is the last substep, or the one after which stepFrame
    // finds no time left (step() advances the clock by exactly double(dt)).
    const double frameEnd = double(mRun.frame + 1) / double(mSettings.frameRate);
    const double tolerance = sph::frameEndTolerance(mSettings.frameRate);
    int substep = 0;
    sph::advanceRunOneFrame(
        mRun, mSettings.frameRate, mSettings.substeps, [this] { return stableTimeStep(); },
        [&](Real dt) {
        const bool last = mSettings.substeps > 0
                              ? ++substep == mSettings.substeps
                              : !(frameEnd - (mRun.time + double(dt)) > tolerance);
        step(dt, last);
        });
    // The frame's end snaps the clock to frameEnd; the bodies' clocks follow (their placement
    // at time() must be their state, with no extrapolation over a rounding difference).
    for (const auto& solid : mSolids) {
        if (solid->body) solid->body->rigid.setTime(mRun.time);
    }
}

} // namespace ghost
} // namespace ghostfx
