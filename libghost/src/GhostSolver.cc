/// @file   GhostSolver.cc
/// @brief  Ghost SPH [SB12] Algorithm 3: set-up, ghost air and solid layers, the step, collision
///         projection, time stepping and blow-up detection. Basic SPH is in BasicSph.cc.
#include "ghostfx/ghost/GhostSolver.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/FrameSteps.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/PoissonSampler.h>
#include <ghostfx/sph/SphDensity.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

namespace ghostfx {
namespace ghost {

using namespace sph;

namespace {

/// Names of the solver's particle channels.
constexpr const char* VSTAR = "vstar";             ///< v* = v + dt a, Algorithm 3 line 14
constexpr const char* SOLID_NORMAL = "normal";     ///< ghost solid: outward normal, world frame
constexpr const char* SOLID_VELOCITY = "solid_v";  ///< ghost solid: velocity of its solid (m/s)
constexpr const char* SOLID_LOCAL = "solid_x";     ///< ghost solid: position in its solid's frame
constexpr const char* SOLID_LOCAL_NORMAL = "solid_n"; ///< ghost solid: normal in its solid's frame
constexpr const char* SOLID_INDEX = "solid_index"; ///< ghost solid: which solid (index)
constexpr const char* AIR_WEIGHT = "air_weight";   ///< ghost air: fade weight, mass = weight m
constexpr const char* AIR_TARGET = "air_target";   ///< ghost air: 1 fading in / kept, 0 fading out

double secondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Tait equation of state ([SB12] Sec. 3, Monaghan 1994): p = k ((rho / rho0)^7 - 1).
inline Real taitPressure(Real rho, Real rho0, Real k)
{
    const Real q = rho / rho0;
    const Real q2 = q * q;
    return k * (q2 * q2 * q2 * q - Real(1));
}

} // namespace

/// A solid: its level set (in its local frame) and its rigid motion.
struct GhostSolver::Solid : sph::MovingLevelSet
{
};

/// A continuous liquid source.
struct GhostSolver::Emitter
{
    LevelSet shape;
    Vec3 velocity;
    double start, end;
};

GhostSolver::GhostSolver(const GhostSettings& settings)
    : mSettings(settings)
    , mKernel((settings.validate(), settings.supportRadius()))
    , mGrid(settings.supportRadius())
{
    // Model only what the scene needs: v* is used by every step of both methods; the ghost air
    // channels only by Ghost SPH (Basic SPH has no air); the solid channels come with the first
    // solid (ensureSolidChannels).
    mParticles.addVectorChannel(VSTAR);
    if (mSettings.method == Method::Ghost) {
        mParticles.addScalarChannel(AIR_WEIGHT, Real(1));
        mParticles.addScalarChannel(AIR_TARGET, Real(1));
    }
}

GhostSolver::~GhostSolver() = default;

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
}

void GhostSolver::setStepObserver(StepObserver observer) { mObserver = std::move(observer); }

// Set-up ---------------------------------------------------------------------------------------

void GhostSolver::addSolid(const LevelSet& solid, const Vec3& velocity)
{
    if (!isFinite(velocity)) {
        throw ValueError(msg("solid '", solid.name(), "': velocity is not finite"));
    }
    addMovingSolid(solid, [velocity](double t) {
        RigidTransform xf;
        xf.translation = velocity * Real(t);
        return xf;
    });
}

void GhostSolver::addMovingSolid(const LevelSet& solid, RigidMotion motion)
{
    if (!motion) throw ValueError(msg("solid '", solid.name(), "': no motion given"));
    ensureSolidChannels();
    mSolids.push_back(std::make_unique<Solid>(Solid{{solid, std::move(motion)}}));
    // A solid the restored state already holds keeps its restored particles: sampling it again
    // would duplicate them (and, with a seed that depends on the step, differ from them).
    if (mSolids.size() > mRestoredSolids) sampleSolid(mSolids.size() - 1);
}

void GhostSolver::ensureSolidChannels()
{
    mParticles.addVectorChannel(SOLID_NORMAL);
    mParticles.addVectorChannel(SOLID_VELOCITY);
    mParticles.addVectorChannel(SOLID_LOCAL);
    mParticles.addVectorChannel(SOLID_LOCAL_NORMAL);
    mParticles.addScalarChannel(SOLID_INDEX, Real(-1));
}

void GhostSolver::setSolidShape(std::size_t solidIndex, const LevelSet& shape)
{
    if (solidIndex >= mSolids.size()) {
        throw ValueError(msg("setSolidShape: solid ", solidIndex, " does not exist (",
                             mSolids.size(), " solids)"));
    }
    // Drop the old ghosts of this solid, then sample the new shape.
    const auto& index = mParticles.scalarChannel(SOLID_INDEX);
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    for (std::size_t i = 0; i < remove.size(); ++i) {
        const ParticleKind k = mParticles.kinds()[i];
        remove[i] = (k == ParticleKind::GhostSolid || k == ParticleKind::Boundary) &&
                    std::size_t(index[i]) == solidIndex;
    }
    mParticles.removeIf(remove);
    mSolids[solidIndex]->shape = shape;
    sampleSolid(solidIndex);
}

void GhostSolver::sampleSolid(std::size_t solidIndex)
{
    const Solid& body = *mSolids[solidIndex];
    const LevelSet& solid = body.shape;
    const RigidTransform xf = body.at(mTime);
    if (!isFinite(xf.translation)) {
        throw ValueError(msg("solid '", solid.name(), "': motion gives a non-finite placement at t = ",
                             mTime, " s"));
    }

    // [SB12] Sec. 4.4 / 4.5: ghost solid particles in a band one kernel radius deep, sampled
    // like liquid (surface, relaxation, interior, relaxation). Basic SPH uses the same layer as
    // its boundary particles.
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.bandDepth = mSettings.supportRadius();
    ps.seed = mSettings.seed + 1000003ULL * (solidIndex + 1) + mStep;
    const SampleSet samples = PoissonDiskSampler(ps).sampleVolume(solid);

    // Outward normal of each ghost from its nearest surface sample: phi is clamped beyond the
    // narrow band, which is often thinner than a kernel radius.
    std::vector<Vec3> surface;
    std::vector<Vec3> surfaceNormal;
    for (std::size_t i = 0; i < samples.size(); ++i) {
        if (samples.onSurface[i]) {
            surface.push_back(samples.positions[i]);
            surfaceNormal.push_back(solid.normal(samples.positions[i]));
        }
    }
    NeighborGrid surfaceGrid(mSettings.supportRadius());
    surfaceGrid.build(surface);

    const Index first = Index(mParticles.size());
    std::vector<Vec3> positions(samples.positions);
    for (Vec3& x : positions) x = xf.toWorld(x);
    const ParticleKind kind =
        mSettings.method == Method::Ghost ? ParticleKind::GhostSolid : ParticleKind::Boundary;
    mParticles.addBatch(positions, mMass, kind);
    auto& normals = mParticles.vectorChannel(SOLID_NORMAL);
    auto& localNormals = mParticles.vectorChannel(SOLID_LOCAL_NORMAL);
    auto& locals = mParticles.vectorChannel(SOLID_LOCAL);
    auto& solidV = mParticles.vectorChannel(SOLID_VELOCITY);
    auto& index = mParticles.scalarChannel(SOLID_INDEX);
    for (std::size_t k = 0; k < samples.size(); ++k) {
        const Index s = surfaceGrid.nearest(samples.positions[k], Real(2) * mSettings.supportRadius(),
                                            [](Index) { return true; });
        localNormals[first + k] = s == INVALID_INDEX ? Vec3(0) : surfaceNormal[s];
        normals[first + k] = xf.rotation * localNormals[first + k];
        locals[first + k] = samples.positions[k];
        index[first + k] = Real(solidIndex);
        solidV[first + k] = body.velocity(samples.positions[k], mTime);
        mParticles.velocities()[first + k] = solidV[first + k];
    }
}

std::size_t GhostSolver::addLiquid(const LevelSet& shape, const Vec3& velocity)
{
    if (mRestored) {
        throw ValueError(msg("liquid '", shape.name(), "': cannot add liquid after restoreState(); "
                             "the restored particles already hold the liquid (skip liquid "
                             "bodies when resuming)"));
    }
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.seed = mSettings.seed + 7919ULL * (mParticles.count(ParticleKind::Liquid) + 1);
    SampleSet samples = PoissonDiskSampler(ps).sampleVolume(shape);
    // Liquid inside a solid is not liquid, and liquid samples on a surface shared with a solid
    // would sit on top of the solid's own surface samples: keep half a spacing of clearance.
    std::vector<Vec3> kept;
    kept.reserve(samples.size());
    for (const Vec3& x : samples.positions) {
        if (!blockedBySolid(x)) kept.push_back(x);
    }
    addLiquidParticles(kept, velocity);
    return kept.size();
}

void GhostSolver::addLiquidParticles(const std::vector<Vec3>& positions, const Vec3& velocity)
{
    if (mRestored) {
        throw ValueError("cannot add liquid particles after restoreState(); the restored particles "
                         "already hold the liquid (skip liquid bodies when resuming)");
    }
    for (std::size_t k = 0; k < positions.size(); ++k) {
        if (!isFinite(positions[k])) {
            throw ValueError(msg("liquid particle ", k, " has a non-finite position"));
        }
    }
    const Index first = mParticles.addBatch(positions, mMass, ParticleKind::Liquid);
    std::fill(mParticles.velocities().begin() + first, mParticles.velocities().end(), velocity);
}

bool GhostSolver::blockedBySolid(const Vec3& x) const
{
    // Liquid keeps half a spacing from solid surfaces, where the solid's own surface samples sit.
    const Real clearance = Real(0.5) * mSettings.spacing;
    for (const auto& solid : mSolids) {
        if (solid->phi(x, mTime) < clearance) return true;
    }
    return false;
}

void GhostSolver::addEmitter(const LevelSet& shape, const Vec3& velocity, double startTime,
                             double endTime)
{
    if (!isFinite(velocity)) {
        throw ValueError(msg("emitter '", shape.name(), "': velocity is not finite"));
    }
    if (!(endTime > startTime) || !(startTime >= 0)) {
        throw ValueError(msg("emitter '", shape.name(), "': start ", startTime, " s, end ", endTime,
                             " s: expected 0 <= start < end"));
    }
    mEmitters.push_back(std::make_unique<Emitter>(Emitter{shape, velocity, startTime, endTime}));
}

void GhostSolver::emit()
{
    for (std::size_t e = 0; e < mEmitters.size(); ++e) {
        const Emitter& em = *mEmitters[e];
        if (mTime < em.start || mTime >= em.end) continue;
        const Real R = mSettings.supportRadius();
        const Aabb box = em.shape.bounds();
        const Aabb near = box.padded(R);

        // Air inside the emitter gives way to the liquid at once.
        std::vector<std::uint8_t> remove(mParticles.size(), 0);
        bool anyAir = false;
        for (std::size_t i = 0; i < mParticles.size(); ++i) {
            if (mParticles.kinds()[i] == ParticleKind::GhostAir &&
                em.shape.phi(mParticles.positions()[i]) < Real(0)) {
                remove[i] = anyAir = true;
            }
        }
        if (anyAir) mParticles.removeIf(remove);

        // Seeds: liquid already in the emitter; obstacles: every other particle nearby.
        std::vector<Vec3> seeds, obstacles;
        for (std::size_t i = 0; i < mParticles.size(); ++i) {
            const Vec3& x = mParticles.positions()[i];
            if (!near.contains(x)) continue;
            if (mParticles.kinds()[i] == ParticleKind::Liquid && em.shape.phi(x) < Real(0)) {
                seeds.push_back(x);
            } else {
                obstacles.push_back(x);
            }
        }
        std::vector<Vec3> fresh;
        if (seeds.empty()) {
            // Nothing to grow from: fill the emitter as an initial liquid body ([SB12] Sec. 4.5).
            PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
            ps.seed = mSettings.seed + 31337ULL * (e + 1) + mStep;
            for (const Vec3& x : PoissonDiskSampler(ps).sampleVolume(em.shape).positions) {
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
            ps.seed = mSettings.seed ^ (0xc2b2ae3d27d4eb4fULL * (mStep + 1) + e);
            auto accept = [&](const Vec3& x) {
                return em.shape.phi(x) < Real(0) && !blockedBySolid(x);
            };
            fresh = PoissonDiskSampler(ps).sampleFromSeeds(seeds, obstacles, accept, box);
        }
        if (fresh.empty()) continue;
        const Index first = mParticles.addBatch(fresh, mMass, ParticleKind::Liquid);
        std::fill(mParticles.velocities().begin() + first, mParticles.velocities().end(), em.velocity);
        mEmitted += fresh.size();
    }
}

void GhostSolver::applyKillBox()
{
    const Aabb& box = mSettings.killBox;
    if (box.empty()) return;
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    std::size_t killed = 0;
    bool any = false;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        const ParticleKind k = mParticles.kinds()[i];
        if ((k == ParticleKind::Liquid || k == ParticleKind::GhostAir) &&
            !box.contains(mParticles.positions()[i])) {
            remove[i] = any = true;
            killed += k == ParticleKind::Liquid;
        }
    }
    if (any) mParticles.removeIf(remove);
    mKilled += killed;
}

void GhostSolver::initialize()
{
    if (mInitialized) return;
    if (mParticles.count(ParticleKind::Liquid) == 0) emit();
    if (mParticles.count(ParticleKind::Liquid) == 0) {
        throw ValueError("liquid solver: no liquid particles (add a liquid body, particles, or an "
                         "emitter active at the start)");
    }
    if (mSettings.method == Method::Ghost) resampleAir();

    if (mMass == Real(0)) {
        // [SB12] Sec. 4.6: scale the mass so the liquid's mean density is rho0, measured with a
        // ghost air layer in place so every liquid particle has a complete neighbourhood. Basic
        // SPH gets the same mass (its air layer is sampled for the measurement only), so the
        // two methods start from the same state and differ only in how they treat the surface.
        std::vector<Vec3> positions = mParticles.positions();
        std::vector<std::uint8_t> liquid(positions.size());
        for (std::size_t i = 0; i < liquid.size(); ++i) {
            liquid[i] = mParticles.kinds()[i] == ParticleKind::Liquid;
        }
        if (mSettings.method == Method::Basic) {
            GhostSettings probeSettings = mSettings;
            probeSettings.method = Method::Ghost;
            GhostSolver probe(probeSettings);
            // The probe shares the solids and takes this solver's boundary particles as its
            // ghost solids: sampling them again would cost as much as the first time.
            for (const auto& solid : mSolids) probe.mSolids.push_back(std::make_unique<Solid>(*solid));
            std::vector<Vec3> boundary;
            for (std::size_t i = 0; i < positions.size(); ++i) {
                if (mParticles.kinds()[i] == ParticleKind::Boundary) boundary.push_back(positions[i]);
            }
            probe.mParticles.addBatch(boundary, Real(0), ParticleKind::GhostSolid);
            std::vector<Vec3> liquidOnly;
            for (std::size_t i = 0; i < liquid.size(); ++i) {
                if (liquid[i]) liquidOnly.push_back(positions[i]);
            }
            probe.addLiquidParticles(liquidOnly);
            probe.resampleAir();
            positions = probe.mParticles.positions();
            liquid.assign(positions.size(), 0);
            for (std::size_t i = 0; i < liquid.size(); ++i) {
                liquid[i] = probe.mParticles.kinds()[i] == ParticleKind::Liquid;
            }
        }
        setParticleMass(massForRestDensity(positions, mKernel, mSettings.restDensity, liquid));
    } else {
        setParticleMass(mMass);
    }

    if (mSettings.method == Method::Basic) {
        mLennardJones = mSettings.lennardJonesStrength;
        if (mLennardJones == Real(0)) {
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
            mLennardJones = g > Real(0) ? Real(5) * g * std::max(hi - lo, mSettings.spacing)
                                        : sqr(Real(0.1) * mSettings.soundSpeed());
        }
    }
    mInitialized = true;
}

// [SB12] Sec. 4.3: ghost air ------------------------------------------------------------------

void GhostSolver::resampleAir()
{
    const auto start = std::chrono::steady_clock::now();
    const Real R = mSettings.supportRadius();
    const Real r = PoissonSettings::SB12_RADIUS_FACTOR * mSettings.spacing;
    const double time = mTime;

    std::vector<Vec3> liquid, liquidV;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::Liquid) continue;
        liquid.push_back(mParticles.positions()[i]);
        liquidV.push_back(mParticles.velocities()[i]);
    }
    if (liquid.empty()) return;
    NeighborGrid liquidGrid(R);
    liquidGrid.build(liquid);

    // The liquid body: particles with at least one liquid neighbour. Isolated particles move
    // ballistically and get no air ([SB12] Sec. 4.5); like the solids they are obstacles the
    // new air keeps r away from. Air lives within a kernel radius of the body only, so escaped
    // spray neither attracts air nor stretches the sampling region.
    std::vector<Vec3> body, bodyV, obstacles;
    Aabb bounds;
    for (std::size_t i = 0; i < liquid.size(); ++i) {
        int n = 0;
        liquidGrid.forEachNeighbor(Index(i), [&](Index, const Vec3&, Real) { ++n; });
        if (n > 1) {
            body.push_back(liquid[i]);
            bodyV.push_back(liquidV[i]);
            bounds.expand(liquid[i]);
        } else {
            obstacles.push_back(liquid[i]);
        }
    }
    NeighborGrid bodyGrid(R);
    bodyGrid.build(body);
    auto nearBody = [&](const Vec3& x, Real* distance = nullptr) {
        return bodyGrid.nearest(x, R, [](Index) { return true; }, distance);
    };

    auto insideSolid = [&](const Vec3& x) {
        for (const auto& solid : mSolids) {
            if (solid->phi(x, time) < Real(0)) return true;
        }
        return false;
    };
    // Inside the liquid: its smoothed indicator sum_j W(x - x_j) / n0, with n0 = rho0 / m the
    // interior value, exceeds one half there (the free surface is its half level). The
    // Poisson test alone is not enough: a relaxed liquid has holes a little wider than r
    // (tests/sph/test_sampler.cc measures 1.05 - 1.1 r), and air seeded into them would sit
    // inside the liquid with p = 0, adding mass where there is no free surface.
    // Interior value n0 of sum_j W: rho0 / m once the mass is known; before (the first layer)
    // the 75th percentile of the liquid particles' own sums, which lies in the interior.
    Real n0 = 0;
    if (mMass > Real(0)) {
        n0 = mSettings.restDensity / mMass;
    } else {
        std::vector<Real> sums(liquid.size());
        parallel::forEach(0, liquid.size(), [&](std::size_t i) {
            Real sum = 0;
            liquidGrid.forEachNeighbor(Index(i), [&](Index, const Vec3&, Real rij) {
                sum += mKernel.W(rij);
            });
            sums[i] = sum;
        });
        std::nth_element(sums.begin(), sums.begin() + sums.size() * 3 / 4, sums.end());
        n0 = sums[sums.size() * 3 / 4];
    }
    // The indicator counts ghost solids too: the thin gap between liquid and a wall is not
    // free surface, and air there would hold the liquid off the wall.
    std::vector<Vec3> dense = liquid;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] == ParticleKind::GhostSolid) dense.push_back(mParticles.positions()[i]);
    }
    NeighborGrid denseGrid(R);
    denseGrid.build(dense);
    auto insideLiquid = [&](const Vec3& x) {
        Real sum = 0;
        denseGrid.forEachInRadius(x, R, [&](Index, const Vec3&, Real rij) { sum += mKernel.W(rij); });
        return sum > Real(0.5) * n0;
    };

    // Keep the air that is still where the layer should be: within a kernel radius of the
    // liquid body, no closer to it than a fraction of r, outside solids and the liquid, and not
    // crowded (air advected with converging liquid bunches up: of two air particles closer than
    // that fraction of r, the later one goes). The rest fades out, and new air fades in, over the
    // steps until the next resampling: replacing the whole layer at once (as [SB12] Sec. 4.3
    // describes) makes the surface density jump by a few percent at every resampling, which with
    // the paper's soft stiffness pumps energy into the liquid; fading is the remedy [SB12]
    // Sec. 4.7 suggests.
    const Real keepDistance = mSettings.airKeepFraction * r;
    auto& target = mParticles.scalarChannel(AIR_TARGET);
    const std::size_t n = mParticles.size();
    std::vector<std::uint8_t> keep(n, 0);
    parallel::forEach(0, n, [&](std::size_t i) {
        if (mParticles.kinds()[i] != ParticleKind::GhostAir || target[i] == Real(0)) return;
        const Vec3& x = mParticles.positions()[i];
        Real d = -1;
        keep[i] = nearBody(x, &d) != INVALID_INDEX && d >= keepDistance && !insideSolid(x) &&
                  !insideLiquid(x);
    });
    if (keepDistance > Real(0)) {
        std::vector<Vec3> airX;
        std::vector<std::size_t> airIndex;
        for (std::size_t i = 0; i < n; ++i) {
            if (keep[i]) { airX.push_back(mParticles.positions()[i]); airIndex.push_back(i); }
        }
        NeighborGrid airGrid(keepDistance);
        airGrid.build(airX);
        for (std::size_t a = 0; a < airX.size(); ++a) {
            airGrid.forEachNeighbor(Index(a), [&](Index b, const Vec3&, Real) {
                if (b < a && keep[airIndex[b]]) keep[airIndex[a]] = 0;
            });
        }
    }
    std::vector<Vec3> seeds = body;
    for (std::size_t i = 0; i < n; ++i) {
        const ParticleKind k = mParticles.kinds()[i];
        if (k == ParticleKind::GhostAir) {
            if (keep[i]) {
                seeds.push_back(mParticles.positions()[i]);
            } else {
                // Fading air is no obstacle: the new layer cross-fades with it.
                target[i] = Real(0);
            }
        } else if (k != ParticleKind::Liquid) {
            obstacles.push_back(mParticles.positions()[i]);
        }
    }
    if (body.empty()) {
        mTimings.airResampling += secondsSince(start);
        return;
    }

    auto accept = [&](const Vec3& x) {
        return nearBody(x) != INVALID_INDEX && !insideSolid(x) && !insideLiquid(x);
    };
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.volumeAttempts = PoissonSettings::SB12_SEEDED_ATTEMPTS;
    ps.seed = mSettings.seed ^ (0x9e3779b97f4a7c15ULL * (mStep + 1));
    const std::vector<Vec3> air =
        PoissonDiskSampler(ps).sampleFromSeeds(seeds, obstacles, accept, bounds.padded(R));

    const Index first = mParticles.addBatch(air, mMass, ParticleKind::GhostAir);
    // The very first layer is there from the start; later ones fade in.
    const bool fade = mInitialized;
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    // Ghost air velocity: the nearest liquid particle's ([SB12] Sec. 4.3).
    parallel::forEach(first, mParticles.size(), [&](std::size_t i) {
        weight[i] = fade ? Real(0) : Real(1);
        mParticles.masses()[i] = weight[i] * mMass;
        const Index j = nearBody(mParticles.positions()[i]);
        mParticles.velocities()[i] = j == INVALID_INDEX ? Vec3(0) : bodyV[j];
        mParticles.densities()[i] = mSettings.restDensity;
    });
    mTimings.airResampling += secondsSince(start);
}

void GhostSolver::fadeAir()
{
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    const auto& target = mParticles.scalarChannel(AIR_TARGET);
    const Real rate = Real(1) / Real(mSettings.airResampleSteps);
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    bool anyRemoved = false;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::GhostAir) continue;
        weight[i] = target[i] > weight[i] ? std::min(target[i], weight[i] + rate)
                                          : std::max(target[i], weight[i] - rate);
        mParticles.masses()[i] = weight[i] * mMass;
        if (weight[i] == Real(0) && target[i] == Real(0)) remove[i] = anyRemoved = true;
    }
    if (anyRemoved) mParticles.removeIf(remove);
}

// Density -----------------------------------------------------------------------------------------

Index GhostSolver::nearestLiquid(const Vec3& x, Real maxRadius) const
{
    return mGrid.nearestOfKind(x, mParticles.kinds(), ParticleKind::Liquid, maxRadius);
}

void GhostSolver::sortAndComputeDensity()
{
    mGrid.sortParticles(mParticles);
    const auto& x = mParticles.positions();
    const auto& m = mParticles.masses();
    const auto& kind = mParticles.kinds();
    auto& rho = mParticles.densities();
    const Real rho0 = mSettings.restDensity;
    const bool ghost = mSettings.method == Method::Ghost;
    const std::size_t n = mParticles.size();

    // Eq. 1 for liquid particles: Ghost SPH sums over every kind, Basic SPH over liquid only.
    std::vector<std::uint32_t> neighbours(n, 0);
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] != ParticleKind::Liquid) {
            rho[i] = rho0;
            return;
        }
        Real sum = 0;
        std::uint32_t count = 0;
        mGrid.forEachNeighbor(Index(i), [&](Index j, const Vec3&, Real r) {
            if (ghost || kind[j] == ParticleKind::Liquid) {
                sum += m[j] * mKernel.W(r);
                ++count;
            }
        });
        rho[i] = sum;
        neighbours[i] = count;
    });
    const double liquidCount = parallel::sum(0, n, [&](std::size_t i) {
        return kind[i] == ParticleKind::Liquid ? 1.0 : 0.0;
    });
    mMeanNeighbors = parallel::sum(0, n, [&](std::size_t i) { return double(neighbours[i]); }) /
                     std::max(1.0, liquidCount);

    // Algorithm 3 lines 5-7: ghost solid density = density of the nearest liquid particle.
    // The nearest liquid particle is kept for the velocity extrapolation of lines 16-18.
    if (ghost) {
        const Real R = mSettings.supportRadius();
        mNearestLiquid.assign(n, INVALID_INDEX);
        parallel::forEach(0, n, [&](std::size_t i) {
            if (kind[i] != ParticleKind::GhostSolid) return;
            const Index j = nearestLiquid(x[i], R);
            mNearestLiquid[i] = j;
            rho[i] = j == INVALID_INDEX ? rho0 : rho[j];
        });
    }

    // Lines 8-10: pressure from the equation of state (ghost air: rho0, so p = 0).
    auto& p = mParticles.pressures();
    parallel::forEach(0, n, [&](std::size_t i) {
        p[i] = taitPressure(rho[i], rho0, mSettings.stiffness);
    });
}

// The step ---------------------------------------------------------------------------------------

void GhostSolver::step(Real dt)
{
    if (!(dt > Real(0)) || !std::isfinite(dt)) {
        throw ValueError(msg("liquid step: dt = ", dt, " s: expected a finite value > 0"));
    }
    checkRestoredInputs();
    const bool fresh = !mInitialized;
    initialize();
    const auto start = std::chrono::steady_clock::now();
    // Algorithm 3 line 1: new liquid from the emitters (the first step's was added by
    // initialize(), before the mass scaling).
    if (!fresh && !mEmitters.empty()) {
        const auto t0 = std::chrono::steady_clock::now();
        emit();
        mTimings.emission += secondsSince(t0);
    }
    if (mSettings.method == Method::Ghost) stepGhost(dt);
    else stepBasic(dt);

    // Solids move rigidly: every ghost goes to its material point's new place and velocity.
    if (!mSolids.empty()) {
        const double t1 = mTime + double(dt);
        std::vector<RigidTransform> placement;
        for (const auto& solid : mSolids) placement.push_back(solid->at(t1));
        auto& x = mParticles.positions();
        const auto& kind = mParticles.kinds();
        const auto& local = mParticles.vectorChannel(SOLID_LOCAL);
        const auto& localNormal = mParticles.vectorChannel(SOLID_LOCAL_NORMAL);
        const auto& index = mParticles.scalarChannel(SOLID_INDEX);
        auto& normal = mParticles.vectorChannel(SOLID_NORMAL);
        auto& solidV = mParticles.vectorChannel(SOLID_VELOCITY);
        parallel::forEach(0, mParticles.size(), [&](std::size_t i) {
            if (kind[i] != ParticleKind::GhostSolid && kind[i] != ParticleKind::Boundary) return;
            const std::size_t b = std::size_t(index[i]);
            x[i] = placement[b].toWorld(local[i]);
            normal[i] = placement[b].rotation * localNormal[i];
            solidV[i] = mSolids[b]->velocity(local[i], t1);
        });
    }
    mTime += double(dt);
    ++mStep;
    projectOutOfSolids();
    applyKillBox();
    checkBlowUp();
    mTimings.total += secondsSince(start);
    ++mTimings.steps;
    if (mObserver) mObserver(*this, dt);
}

void GhostSolver::stepGhost(Real dt)
{
    // Line 1: resample the air every airResampleSteps steps (the first step always has air),
    // then move every fading air particle's weight one step towards its target.
    if (mStep > 0 && mStep % std::uint64_t(mSettings.airResampleSteps) == 0) resampleAir();
    fadeAir();

    auto t0 = std::chrono::steady_clock::now();
    sortAndComputeDensity();
    mTimings.neighborsAndDensity += secondsSince(t0);

    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& m = mParticles.masses();
    const auto& rho = mParticles.densities();
    const auto& p = mParticles.pressures();
    const auto& kind = mParticles.kinds();
    auto& v = mParticles.velocities();
    auto& vstar = mParticles.vectorChannel(VSTAR);
    const Vec3 g = mSettings.gravity;

    // Lines 11-14: liquid acceleration from gravity and Monaghan's symmetric pressure gradient
    // over every neighbour, v* = v + dt a.
    t0 = std::chrono::steady_clock::now();
    std::vector<Real> accel(n, Real(0));
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] != ParticleKind::Liquid) {
            vstar[i] = v[i];
            return;
        }
        const Real pi = p[i] / sqr(rho[i]);
        Vec3 a = g;
        mGrid.forEachNeighbor(Index(i), [&](Index j, const Vec3& xij, Real r) {
            if (j == i) return;
            a -= m[j] * (pi + p[j] / sqr(rho[j])) * mKernel.gradW(xij, r);
        });
        vstar[i] = v[i] + dt * a;
        accel[i] = a.length();
    });
    mMaxAcceleration = 0;
    for (std::size_t i = 0; i < n; ++i) mMaxAcceleration = std::max(mMaxAcceleration, accel[i]);
    mTimings.pressureForce += secondsSince(t0);

    // Lines 15-18: ghost solid velocity, Eq. 3 (free slip) or the solid's velocity (no slip).
    t0 = std::chrono::steady_clock::now();
    const Real R = mSettings.supportRadius();
    if (mParticles.hasVectorChannel(SOLID_NORMAL)) { // no solid channels: no ghost solids
        const auto& normal = mParticles.vectorChannel(SOLID_NORMAL);
        const auto& solidV = mParticles.vectorChannel(SOLID_VELOCITY);
        const bool freeSlip = mSettings.solidSlip == SolidSlip::Free;
        parallel::forEach(0, n, [&](std::size_t i) {
            if (kind[i] != ParticleKind::GhostSolid) return;
            const Vec3& nrm = normal[i];
            if (!freeSlip) {
                vstar[i] = solidV[i];
                return;
            }
            const Index j = mNearestLiquid[i];
            const Vec3 vl = j == INVALID_INDEX ? solidV[i] : vstar[j];
            vstar[i] = solidV[i].dot(nrm) * nrm + (vl - vl.dot(nrm) * nrm);
        });
    }

    // Lines 19-21: XSPH artificial viscosity on the velocity (Eq. 2), liquid and solid
    // neighbours only: air would bias the outermost particles ([SB12] Sec. 4.3).
    const Real eps = mSettings.xsphEpsilon, epsSolid = mSettings.solidEpsilon;
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] != ParticleKind::Liquid) return;
        Vec3 dv(0);
        mGrid.forEachNeighbor(Index(i), [&](Index j, const Vec3&, Real r) {
            const ParticleKind kj = kind[j];
            if (kj == ParticleKind::GhostAir || j == i) return;
            const Real e = kj == ParticleKind::GhostSolid ? epsSolid : eps;
            dv += (e * m[j] / rho[j] * mKernel.W(r)) * (vstar[j] - vstar[i]);
        });
        v[i] = vstar[i] + dv;
    });

    // Lines 22-25: air takes the new velocity of its nearest liquid particle (searched up to two
    // kernel radii: air advects between resamplings and may drift a little).
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] != ParticleKind::GhostAir) return;
        const Index j = nearestLiquid(x[i], Real(2) * R);
        if (j != INVALID_INDEX) v[i] = v[j];
    });
    // Ghost solids keep their extrapolated velocity for output; their motion is the solid's.
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] == ParticleKind::GhostSolid) v[i] = vstar[i];
    });

    // Lines 26-28: positions of liquid and air.
    auto& xw = mParticles.positions();
    parallel::forEach(0, n, [&](std::size_t i) {
        if (kind[i] == ParticleKind::Liquid || kind[i] == ParticleKind::GhostAir) xw[i] += dt * v[i];
    });
    mTimings.xsphAndBoundary += secondsSince(t0);
}

// Collisions, time stepping, blow-up ---------------------------------------------------------------

void GhostSolver::projectOutOfSolids()
{
    if (mSolids.empty()) return;
    const auto start = std::chrono::steady_clock::now();
    auto& x = mParticles.positions();
    auto& v = mParticles.velocities();
    const auto& kind = mParticles.kinds();
    const double time = mTime;
    std::vector<RigidTransform> placement;
    for (const auto& solid : mSolids) placement.push_back(solid->at(time));
    // [SB12] Sec. 3 "Solid Collisions": a liquid particle inside a solid goes back to its
    // surface (level-set closest point) and loses the velocity that points into the solid.
    parallel::forEach(0, mParticles.size(), [&](std::size_t i) {
        if (kind[i] != ParticleKind::Liquid) return;
        for (std::size_t b = 0; b < mSolids.size(); ++b) {
            const Solid& solid = *mSolids[b];
            const RigidTransform& xf = placement[b];
            const Vec3 local = xf.toLocal(x[i]);
            if (!(solid.shape.phi(local) < Real(0))) continue;
            const SurfaceProjection proj = solid.shape.projectToSurface(local);
            if (!proj.converged) continue; // deeper than the band: left for the blow-up check
            const Vec3 nrm = xf.rotation * solid.shape.normal(proj.point);
            x[i] = xf.toWorld(proj.point);
            const Real vn = (v[i] - solid.velocity(proj.point, time)).dot(nrm);
            if (vn < Real(0)) v[i] -= vn * nrm;
        }
    });
    mTimings.xsphAndBoundary += secondsSince(start);
}

void GhostSolver::checkBlowUp() const
{
    const Real limit = mSettings.speedLimit();
    const Real limit2 = limit * limit;
    const auto& x = mParticles.positions();
    const auto& v = mParticles.velocities();
    const std::size_t n = mParticles.size();
    std::atomic<std::size_t> bad{n};
    parallel::forEach(0, n, [&](std::size_t i) {
        if (isFinite(x[i]) && isFinite(v[i]) && v[i].lengthSqr() <= limit2) return;
        std::size_t expected = bad.load();
        while (i < expected && !bad.compare_exchange_weak(expected, i)) {}
    }, 4096);
    const std::size_t i = bad.load();
    if (i == n) return;
    const char* kind = kindName(mParticles.kinds()[i]);
    if (!isFinite(x[i]) || !isFinite(v[i])) {
        throw NumericalError(msg("liquid solver blew up at frame ", mFrame, ", step ", mStep,
                                 " (t = ", mTime, " s): ", kind, " particle id ", mParticles.ids()[i],
                                 " has a non-finite position or velocity; reduce the time step "
                                 "(substeps / cflNumber) or the stiffness"));
    }
    throw NumericalError(msg("liquid solver blew up at frame ", mFrame, ", step ", mStep, " (t = ",
                             mTime, " s): ", kind, " particle id ", mParticles.ids()[i], " moves at ",
                             v[i].length(), " m/s, beyond maxSpeed = ", limit,
                             " m/s; reduce the time step (substeps / cflNumber) or the stiffness"));
}

Real GhostSolver::stableTimeStep() const
{
    // Acoustic CFL: dt <= cfl h / (c + |v|max); body force: dt <= cfl sqrt(h / |g|).
    const auto& v = mParticles.velocities();
    Real vmax = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (mParticles.kinds()[i] == ParticleKind::Liquid) vmax = std::max(vmax, v[i].length());
    }
    const Real h = mSettings.spacing;
    Real dt = mSettings.cflNumber * h / (mSettings.soundSpeed() + vmax);
    // Force limit (Monaghan 1992): dt <= cfl sqrt(h / |a|max), with the largest acceleration
    // of the last step (gravity before the first), which covers stiff Lennard-Jones walls.
    const Real a = std::max(mMaxAcceleration, mSettings.gravity.length());
    if (a > Real(0)) dt = std::min(dt, mSettings.cflNumber * std::sqrt(h / a));
    return dt;
}

// Save and restore ----------------------------------------------------------------------------------

SolverState GhostSolver::saveState() const
{
    SolverState state;
    state.solver = methodName(mSettings.method);
    state.particles = mParticles;
    state.reals["time"] = mTime;
    state.reals["particle_mass"] = double(mMass);
    state.reals["lennard_jones"] = double(mLennardJones);
    state.reals["max_acceleration"] = double(mMaxAcceleration);
    state.reals["mean_neighbors"] = mMeanNeighbors;
    state.integers["step"] = std::int64_t(mStep);
    state.integers["frame"] = mFrame;
    state.integers["initialized"] = mInitialized ? 1 : 0;
    state.integers["emitted"] = std::int64_t(mEmitted);
    state.integers["killed"] = std::int64_t(mKilled);
    state.integers["solids"] = std::int64_t(mSolids.size());
    state.integers["emitters"] = std::int64_t(mEmitters.size());
    return state;
}

void GhostSolver::restoreState(const SolverState& state)
{
    const std::string method = methodName(mSettings.method);
    if (state.solver != method) {
        throw ValueError(msg("restoreState: the state was saved by the '", state.solver,
                             "' solver, this solver runs '", method, "'; resume with the method "
                             "the run started with"));
    }
    if (mRestored || mInitialized || mStep != 0 || !mParticles.empty() || !mSolids.empty() ||
        !mEmitters.empty()) {
        throw ValueError("restoreState: call it on a freshly constructed solver, before adding "
                         "solids, emitters or liquid and before the first step");
    }
    // Read every key first, so a state missing one leaves the solver untouched.
    const double time = state.real("time");
    const double mass = state.real("particle_mass");
    const double lennardJones = state.real("lennard_jones");
    const double maxAcceleration = state.real("max_acceleration");
    const double meanNeighbors = state.real("mean_neighbors");
    const std::int64_t step = state.integer("step"), frame = state.integer("frame");
    const std::int64_t initialized = state.integer("initialized");
    const std::int64_t emitted = state.integer("emitted"), killed = state.integer("killed");
    const std::int64_t solids = state.integer("solids"), emitters = state.integer("emitters");
    auto requireRange = [](const char* key, std::int64_t value, std::int64_t lo, std::int64_t hi) {
        if (value < lo || value > hi) {
            throw ValueError(msg("restoreState: integer '", key, "' = ", value, ": expected ", lo,
                                 " to ", hi));
        }
    };
    constexpr std::int64_t BIG = std::numeric_limits<std::int64_t>::max();
    requireRange("step", step, 0, BIG);
    requireRange("frame", frame, 0, std::numeric_limits<int>::max());
    requireRange("initialized", initialized, 0, 1);
    requireRange("emitted", emitted, 0, BIG);
    requireRange("killed", killed, 0, BIG);
    requireRange("solids", solids, 0, BIG);
    requireRange("emitters", emitters, 0, BIG);

    // Every solid particle must name a solid the caller will add again.
    const ParticleSet& p = state.particles;
    const std::vector<Real>* index =
        p.hasScalarChannel(SOLID_INDEX) ? &p.scalarChannel(SOLID_INDEX) : nullptr;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const ParticleKind k = p.kinds()[i];
        if (k != ParticleKind::GhostSolid && k != ParticleKind::Boundary) continue;
        if (!index || !((*index)[i] >= Real(0)) || (*index)[i] >= Real(solids)) {
            throw ValueError(msg("restoreState: ", kindName(k), " particle id ", p.ids()[i],
                                 " belongs to no solid of the state (", solids, " solids)"));
        }
    }
    if (mSettings.method == Method::Basic && p.count(ParticleKind::GhostAir) > 0) {
        throw ValueError("restoreState: a 'basic' state holds ghost air particles");
    }

    mParticles = p;
    // States saved by this solver have these channels; a missing one gets what a fresh solver
    // would have.
    mParticles.addVectorChannel(VSTAR);
    if (mSettings.method == Method::Ghost) {
        mParticles.addScalarChannel(AIR_WEIGHT, Real(1));
        mParticles.addScalarChannel(AIR_TARGET, Real(1));
    }
    mTime = time;
    mMass = Real(mass);
    mLennardJones = Real(lennardJones);
    mMaxAcceleration = Real(maxAcceleration);
    mMeanNeighbors = meanNeighbors;
    mStep = std::uint64_t(step);
    mFrame = int(frame);
    mInitialized = initialized != 0;
    mEmitted = std::size_t(emitted);
    mKilled = std::size_t(killed);
    mRestoredSolids = std::size_t(solids);
    mRestoredEmitters = std::size_t(emitters);
    mRestored = true;
}

void GhostSolver::checkRestoredInputs() const
{
    if (mSolids.size() < mRestoredSolids) {
        throw ValueError(msg("liquid solver: the restored state has ", mRestoredSolids,
                             " solids but ", mSolids.size(), " were added after restoreState(); "
                             "add the same solids, in the same order, before stepping"));
    }
    if (mEmitters.size() < mRestoredEmitters) {
        throw ValueError(msg("liquid solver: the restored state has ", mRestoredEmitters,
                             " emitters but ", mEmitters.size(), " were added after "
                             "restoreState(); add the same emitters, in the same order, before "
                             "stepping"));
    }
}

void GhostSolver::advanceFrame()
{
    checkRestoredInputs();
    initialize();
    const double frameEnd = double(mFrame + 1) / double(mSettings.frameRate);
    sph::stepFrame(frameEnd, mSettings.frameRate, mSettings.substeps, [this] { return mTime; },
                   [this] { return stableTimeStep(); }, [this](Real dt) { step(dt); });
    mTime = frameEnd; // no drift from summing substeps
    ++mFrame;
}

} // namespace ghost
} // namespace ghostfx
