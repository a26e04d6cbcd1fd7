/// @file   GhostInternal.h
/// @brief  What the files of GhostSolver share and nobody else needs: the solid record, channel
///         names, the Tait equation, the packed nearest-liquid key and a timer.
#pragma once

#include "ghostfx/ghost/GhostSolver.h"

#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/RigidMotion.h>
#include <ghostfx/sph/Timing.h>
#include <ghostfx/sph/Types.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

namespace ghostfx {
namespace ghost {

/// A continuous liquid source: its shape in its own frame and, for a moving emitter (a hose
/// sweeping a floor), the rigid motion that places it (empty: the shape stays where it is
/// given). Its velocity is the liquid's in its own frame; in the world the liquid leaves at
/// that velocity rotated with the emitter plus the emitter's own velocity where it is.
struct GhostSolver::Emitter : sph::MovingLevelSet
{
    /// A static emitter (give a moving one its `motion`, then placeAt()).
    Emitter(const sph::LevelSet& shape_, const sph::Vec3& velocity_, double start_, double end_)
        : MovingLevelSet{shape_, {}}
        , velocity(velocity_)
        , start(start_)
        , end(end_)
        , box(shape_.bounds())
    {}

    sph::Vec3 velocity; ///< of the liquid leaving it (m/s), in the emitter's frame
    double start, end;
    /// The new liquid's own kinematic viscosity (m^2/s); none: settings.viscosity.
    std::optional<sph::Real> viscosity;
    /// The shape's shadow along the velocity (m^2; 0 without velocity): the emitted volume
    /// per second is |velocity| crossSection, in the emitter's frame.
    double crossSection = 0;
    /// Mass (kg) the emitter owes: rho0 |velocity| crossSection per second of its steps,
    /// less the mass of the particles it added (GhostSolver::emit()).
    double credit = 0;
    /// The fills' Poisson radius, in the sampler's radii r (GhostSolver::limitToCredit).
    double fillScale = 1;
    /// Where placeAt() put a moving emitter (local to world), at `placedTime` (s), and the
    /// world box of its shape there (a static emitter's: its shape's bounds).
    sph::RigidTransform placement;
    double placedTime = 0;
    sph::Aabb box;

    bool moving() const { return bool(motion); }
    /// Place a moving emitter at `time` (s); a static one stays as it is.
    void placeAt(double time);
    /// Level-set value (m) at the world point x where the emitter is placed.
    sph::Real placedPhi(const sph::Vec3& x) const
    {
        return moving() ? shape.phi(placement.toLocal(x)) : shape.phi(x);
    }
    /// x (m, world) in the placed box and inside the placed shape.
    bool contains(const sph::Vec3& x) const { return box.contains(x) && placedPhi(x) < 0; }
    /// The world point of the emitter's local point (m).
    sph::Vec3 placedPoint(const sph::Vec3& local) const
    {
        return moving() ? placement.toWorld(local) : local;
    }
    /// The velocity (m/s, world) the emitter gives liquid at the world point x: `velocity`
    /// rotated with the emitter plus the emitter's velocity at x (translation rate plus
    /// rotation rate times x in the emitter's frame); `velocity` itself for a static one.
    sph::Vec3 liquidVelocity(const sph::Vec3& x) const;
    /// Write liquidVelocity(x[k]) to velocities[k] for every new particle x[k].
    void giveVelocities(const std::vector<sph::Vec3>& x, sph::Vec3* velocities) const;
};

/// A solid: its level set (in its local frame), its rigid motion, and whether it moves (a
/// static solid's particles live in the static block and are never re-placed).
struct GhostSolver::Solid : sph::MovingLevelSet
{
    bool moving;
    /// A dynamic solid's body (its motion places the solid where the body is), else null.
    std::unique_ptr<Body> body;
};

/// A dynamic solid's rigid body and what its coupling keeps (GhostBodies.cc).
struct GhostSolver::Body
{
    explicit Body(const sph::RigidBody& rigid_) : rigid(rigid_) {}

    sph::RigidBody rigid;
    /// The liquid's force and torque as applied last step, after the added-mass filter.
    sph::Vec3d liquidForce{0.0}, liquidTorque{0.0};
    /// The filter's memory: the liquid's impulse (N s) and angular impulse (N m s) gathered and
    /// not yet applied, r dt times the last applied force and torque.
    sph::Vec3d withheldImpulse{0.0}, withheldAngularImpulse{0.0};
    /// This step's, as gathered (before the filter).
    sph::Vec3d gatheredForce{0.0}, gatheredTorque{0.0};
    /// Share of its ghosts the liquid reached this step (the added mass's share).
    double wetShare = 0;
    sph::Vec3d externalForce{0.0}, externalTorque{0.0}; ///< addBodyForce's
    std::vector<sph::Vec3d> contactPoints;              ///< its surface ghosts, in its own frame
    std::size_t ghosts = 0;                             ///< its ghost particles
    double radius = 0; ///< the farthest contact point from the centre of mass (m)
};

namespace detail {

using sph::Index;
using sph::Real;

/// Names of the solver's particle channels (stored in checkpoints: do not rename).
constexpr const char* VSTAR = LiquidStep::VELOCITY_STAR; ///< v* = v + dt a, Algorithm 3 line 14
constexpr const char* SOLID_NORMAL = "normal";     ///< solid particle: outward normal, world frame
constexpr const char* SOLID_INDEX = "solid_index"; ///< solid particle: which solid (index)
constexpr const char* SOLID_VELOCITY = "solid_v";  ///< moving solid particle: velocity (m/s)
constexpr const char* SOLID_LOCAL = "solid_x";     ///< moving solid particle: position, solid frame
constexpr const char* SOLID_LOCAL_NORMAL =
    "solid_n";                                   ///< moving solid particle: normal, solid frame
constexpr const char* AIR_WEIGHT = "air_weight"; ///< ghost air: fade weight, mass = weight m
/// Ghost air, with surface tension only: how far it has faded in, 0 to 1 (SurfaceTension.h).
constexpr const char* AIR_FADE = "air_fade";
constexpr const char* AIR_TARGET = "air_target"; ///< ghost air: 1 fading in / kept, 0 fading out
constexpr const char* DENSITY_KAPPA = "dfsph_k"; ///< DFSPH: density solve's p / rho^2 (warm start)
constexpr const char* DIVERGENCE_KAPPA =
    "dfsph_kv"; ///< DFSPH: divergence solve's term (warm start)
/// DFSPH over several processes: a solve's values handed to the halo copies (refresh)
constexpr const char* DFSPH_SYNC = "dfsph_sync";
constexpr const char* DFSPH_SYNC_VECTOR = "dfsph_sync_v"; ///< the same for G k

/// Size a per-particle step array for n particles, growing its capacity by a thirty-second
/// (as ParticleSet grows) rather than doubling it (GhostSolver::memoryUse counts capacity, and
/// the air count changes a little at every resampling), and fill it with `value`.
template <typename T>
void assignStepArray(std::vector<T>& array, std::size_t n, const T& value)
{
    if (n > array.capacity()) array.reserve(n + n / 32);
    array.assign(n, value);
}
/// The same without filling: the first min(size, n) entries are kept.
template <typename T>
void resizeStepArray(std::vector<T>& array, std::size_t n)
{
    if (n > array.capacity()) array.reserve(n + n / 32);
    array.resize(n);
}

/// parallel::forRange over particles [0, n): each task gets its own copy of `kernel` and a
/// PairBatch of its own, and calls body(lo, hi, kernel, batch) on its range.
template <typename Body>
void forRangeWithBatch(std::size_t n, const sph::CubicSplineKernel& kernel, Body&& body,
                       std::size_t grain = parallel::DEFAULT_GRAIN)
{
    parallel::forRange(
        0, n,
        [&](std::size_t lo, std::size_t hi) {
        const sph::CubicSplineKernel local = kernel;
        sph::PairBatch batch;
        body(lo, hi, local, batch);
        },
        grain);
}

// DFSPH (DfsphPressure.cc; its factors are found in the density pass, DensityPass.cc) -----

/// Liquid and solid neighbours (self included) below which a liquid particle is spray, about a
/// fifth of a full neighbourhood at [SB12]'s 3 h support; another support scales it with the
/// neighbourhood's volume (see minimumNeighbours; DfsphPressure.cc). Measured: with 10 (liquid
/// only) the tomato's stream blew up at frame 8; with 20 liquid only, the still tank's corner
/// particles went unsolved and were pushed into the walls; 20 with the solids holds both.
constexpr int MIN_NEIGHBOURS = 20;

/// MIN_NEIGHBOURS for a kernel support of `supportFactor` h: the same share of a full
/// neighbourhood (20 at 3 h, 6 at 2 h). Kept at 20 for 2 h, the top layer of a still tank went
/// unsolved (Dfsph.StillTankAtTwoSpacingsSupportHoldsTheDensityLimit).
inline int minimumNeighbours(sph::Real supportFactor)
{
    const double ratio = double(supportFactor) / 3.0;
    return int(std::lround(MIN_NEIGHBOURS * ratio * ratio * ratio));
}

/// The wall's share c of DfsphPressure.cc's file comment: 2 for mirrored ghost solids, 1 for the
/// liquid particle's own pressure term.
inline sph::Real wallShare(const DfsphSettings& opt)
{
    return opt.wallPressure == DfsphSettings::WallPressure::Mirror ? sph::Real(2) : sph::Real(1);
}

/// Tait equation of state ([SB12] Sec. 3, Monaghan 1994): p = k ((rho / rho0)^7 - 1).
inline Real taitPressure(Real rho, Real rho0, Real k)
{
    const Real q = rho / rho0;
    const Real q2 = q * q;
    return k * (q2 * q2 * q2 * q - Real(1));
}

/// Nearest-liquid key of a solid particle: the distance in the high 32 bits (as float bits,
/// which order like the values for r >= 0) and the liquid index in the low ones, so the
/// smallest key is the nearest liquid particle and, at equal distance, the lowest index. Taking
/// the minimum is order-independent: any thread count gives the same answer.
constexpr std::uint64_t NO_LIQUID = ~std::uint64_t(0);
/// A liquid particle the collision projection pushed out of no dynamic solid this step.
constexpr std::uint32_t NO_BODY_HIT = ~std::uint32_t(0);
inline std::uint64_t nearestKey(Real r, Index liquid)
{
    const float f = float(r);
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    return std::uint64_t(bits) << 32 | liquid;
}
inline Index nearestIndex(std::uint64_t key) { return Index(key & 0xffffffffu); }

/// fn(s, j) for each particle s of a solid block (GhostSolver::SolidBlock) that some liquid
/// particle reached this step, with j its nearest liquid particle (Algorithm 3 lines 5-7), in
/// parallel. The order of `touched` depends on the threads; fn must not.
template <typename Block, typename Fn>
void forEachReachedSolid(const Block& block, Fn&& fn)
{
    parallel::forEach(
        0, block.touched.size(),
        [&](std::size_t t) {
        const Index s = block.touched[t];
        fn(s, nearestIndex(block.nearest[s]));
        },
        1024);
}

using sph::secondsSince;

/// DFSPH's CFL step at number `cfl`: dt <= cfl h / |v|max ([BK15] Sec. 4.4) and gravity's
/// force limit cfl sqrt(h / |g|), within [minTimeStep, maxTimeStep] (GhostSolver::
/// stableTimeStep). The pressure's acceleration is left out: the solves' velocity change is
/// whatever moves a particle's density error out within the step, about e h / dt, so an
/// acceleration of e h / dt^2 that shortened the next step asked the next solve for a larger
/// one, and the steps shrank geometrically to minTimeStep (a tap at 2.5 h support and CFL
/// 0.1: 1 ms to 10 us in 3 ms of simulated time, a particle thrown at 8.8 m/s;
/// bench/history/diary-2026-11.md, "DFSPH: the pressure out of the step's force limit"). Its
/// displacement is bounded by the velocity CFL of the step after.
inline Real dfsphTimeStep(const GhostSettings& s, Real fastest, Real cfl)
{
    const DfsphSettings& d = s.dfsph;
    Real dt = fastest > Real(0) ? cfl * s.spacing / fastest : d.maxTimeStep;
    const Real g = s.gravity.length();
    if (g > Real(0)) dt = std::min(dt, cfl * std::sqrt(s.spacing / g));
    return std::clamp(dt, d.minTimeStep, d.maxTimeStep);
}

} // namespace detail
} // namespace ghost
} // namespace ghostfx
