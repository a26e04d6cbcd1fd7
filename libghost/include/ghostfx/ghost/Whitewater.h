/// @file   Whitewater.h
/// @brief  Spray, foam and bubbles from a liquid's particles: Ihmsen, Akinci, Gissler and
///         Teschner 2012, "Unified spray, foam and bubbles for particle-based fluids" (The
///         Visual Computer 28(6)), as secondary particles that never act on the liquid.
/// @details Each frame (or step) of length dt, from the liquid's positions and velocities:
///
///          1. Potentials of each liquid particle i, over its liquid neighbours j within the
///             kernel support H, with the weight W~(r) = 1 - r / H ([IAGT12] Eq. 1):
///             - trapped air: the W~-weighted mean of |v_ij| (1 - v^_ij . x^_ij) (m/s): large
///               where neighbours move into each other ([IAGT12] Eq. 2);
///             - wave crest: the curvature div n^ (1/m) of a surface particle whose velocity
///               relative to its neighbours' mean points out of the liquid (v^ . n^ >= 0.6,
///               [IAGT12] Eqs. 4-6) at `waveCrestSpeed` or more along n^; n^ is the outward
///               normal of the liquid's colour field;
///             - energy: its specific kinetic energy |v|^2 / 2 (J/kg; [IAGT12] Eq. 7).
///             Each is clamped between a minimum and a maximum to [0, 1] ([IAGT12] Eq. 3).
///             Velocities enter the first two only as differences, so a liquid moving as a
///             whole (a still tank, a drop in free fall) makes no whitewater.
///          2. New particles: V_i Phi_k (k_ta Phi_ta + k_wc Phi_wc) dt of them, V_i = h^3 the
///             particle's volume and the rates k in particles per m^3 of liquid per second, so
///             the amount does not change with the spacing ([IAGT12] Eq. 8 counts per
///             particle). They are placed uniformly in a cylinder of radius h / 2 around x_i
///             along v_i, |v_i| dt long, and move at v_i ([IAGT12] Sec. 4.4).
///          3. Classes by the liquid fraction c(x) = sum_j h^3 W(x - x_j) at each particle
///             (1 inside the liquid, about 1/2 at its surface, 0 in the air): spray below
///             `sprayBelow`, bubbles above `bubbleAbove`, foam between ([IAGT12] Sec. 5 counts
///             neighbours instead, which depends on the spacing).
///          4. Motion over dt ([IAGT12] Eqs. 9-11): spray falls with gravity and the air's drag
///             towards rest; foam moves with the liquid's velocity there (the kernel-weighted
///             mean of its neighbours'); bubbles rise against gravity and are dragged towards the
///             liquid's velocity. Foam ages and dissolves after a lifetime drawn at birth
///             between `foamLifetimeMin` and `foamLifetimeMax` (its age counts only while it is
///             foam). Particles outside the kill box or inside a solid, or whose path over dt
///             went through one, are removed.
///
///          Deterministic whatever the input's order and the thread count: the liquid is sorted
///          by particle id first, and the random numbers of liquid particle i at generation
///          g come from a generator seeded by (seed, id, g).
#pragma once

#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/SettingSpec.h>
#include <ghostfx/sph/SolverState.h>
#include <ghostfx/sph/Types.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace ghostfx {
namespace ghost {

using sph::Real;
using sph::Vec3;

/// A whitewater particle's class, as files store it ("type" 0, 1, 2).
enum class WhitewaterType : std::int32_t
{
    Spray = 0,
    Foam = 1,
    Bubble = 2
};

struct WhitewaterSettings
{
    /// Trapped-air potential clamp (m/s).
    Real trappedAirMin = Real(0.2), trappedAirMax = Real(1);
    /// Wave-crest potential clamp: the surface's curvature (1/m).
    Real waveCrestMin = Real(20), waveCrestMax = Real(80);
    /// A crest is a surface particle moving out of the liquid at least this fast (m/s)
    /// relative to its neighbours' mean (and within 53 degrees of the normal).
    Real waveCrestSpeed = Real(0.2);
    /// Energy potential clamp: specific kinetic energy (J/kg).
    Real energyMin = Real(0.5), energyMax = Real(5);
    /// Particles made per m^3 of liquid per second at full potentials (trapped air, crests).
    Real trappedAirRate = Real(1e8), waveCrestRate = Real(1e8);
    /// Liquid fraction c below which a particle is spray, above which it is a bubble.
    Real sprayBelow = Real(0.2), bubbleAbove = Real(0.7);
    /// Spray's drag towards still air (1/s).
    Real sprayDrag = Real(0.5);
    /// A bubble's buoyancy as a multiple of -gravity, and its drag towards the liquid (1/s).
    /// (With the defaults a bubble rises through still liquid at 1.5 g / 50 = 0.29 m/s, as
    /// millimetre air bubbles in water do.)
    Real bubbleBuoyancy = Real(1.5), bubbleDrag = Real(50);
    /// Foam dissolves after a lifetime drawn uniformly from [min, max] (s).
    Real foamLifetimeMin = Real(1), foamLifetimeMax = Real(3);
    std::uint64_t seed = 0;

    /// Throws ValueError naming the first field out of range or a min above its max.
    void validate() const;
};

/// The whitewater settings, each declared once: the keys of a scene's `settings.whitewater`,
/// their ranges, units and meanings (docs/scene-format.md lists them).
const sph::SettingTable<WhitewaterSettings>& whitewaterSettingTable();

/// The liquid a whitewater step reads: positions and velocities as single-precision numbers
/// (as points files hold them, so that a run inline and a post-process over its files see the
/// same liquid) and particle ids.
struct LiquidSnapshot
{
    std::vector<Vec3> positions, velocities;
    std::vector<sph::ParticleId> ids;
    Real spacing = Real(0.02);
    Real supportFactor = Real(3);
    Vec3 gravity{0, Real(-9.81), 0};

    /// The liquid particles of `particles`, rounded to single precision as a points file
    /// holds them.
    static LiquidSnapshot fromParticles(const sph::ParticleSet& particles, Real spacing,
                                        Real supportFactor, const Vec3& gravity);
};

class Whitewater
{
public:
    explicit Whitewater(const WhitewaterSettings& settings);

    /// Solids, as a signed distance (m, negative inside); none by default.
    void setSolids(std::function<Real(const Vec3&)> phi) { mSolidPhi = std::move(phi); }
    /// Particles leaving this box are removed; an empty box (the default) keeps them all.
    void setKillBox(const sph::Aabb& box) { mKillBox = box; }

    /// Move the whitewater over dt (s) in `liquid`, then add the new particles the liquid
    /// makes over dt.
    void step(const LiquidSnapshot& liquid, Real dt);

    std::size_t size() const { return mPositions.size(); }
    std::size_t count(WhitewaterType type) const;
    const std::vector<Vec3>& positions() const { return mPositions; }
    const std::vector<Vec3>& velocities() const { return mVelocities; }
    const std::vector<sph::ParticleId>& ids() const { return mIds; }
    const std::vector<WhitewaterType>& types() const { return mTypes; }
    const std::vector<Real>& ages() const { return mAges; }
    /// Particles made so far, all steps.
    std::uint64_t made() const { return std::uint64_t(mNextId); }

    /// Everything a run needs to continue exactly (solver "whitewater"): the particles with
    /// their channels "type", "age" and "life" (the foam lifetime left), the next id and the
    /// generation count.
    sph::SolverState saveState() const;
    /// Continue from saveState()'s state (of a Whitewater with the same settings). ValueError
    /// for another solver's state or a damaged one.
    void restoreState(const sph::SolverState& state);

private:
    struct Field; // the liquid's neighbour grid and per-particle sums (Whitewater.cc)
    void advect(const Field& field, Real dt);
    /// Whether the straight path from `from` to `to` passes through a solid (h: the spacing).
    bool crossesSolid(const Vec3& from, const Vec3& to, double h) const;
    void classify(const Field& field);
    void remove();
    void generate(const Field& field, Real dt);
    void emit(const Field& field, std::size_t i, std::size_t count, Real dt);

    WhitewaterSettings mSettings;
    std::function<Real(const Vec3&)> mSolidPhi;
    sph::Aabb mKillBox;
    std::uint64_t mGeneration = 0;
    sph::ParticleId mNextId = 0;
    std::vector<Vec3> mPositions, mVelocities;
    std::vector<sph::ParticleId> mIds;
    std::vector<WhitewaterType> mTypes;
    std::vector<Real> mAges, mLives;
};

} // namespace ghost
} // namespace ghostfx
