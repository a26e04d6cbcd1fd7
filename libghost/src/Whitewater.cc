/// @file   Whitewater.cc
/// @brief  Spray, foam and bubbles from a liquid's particles after [IAGT12] (Whitewater.h).
#include "ghostfx/ghost/Whitewater.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/Random.h>
#include <ghostfx/sph/SettingSpec.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

namespace ghostfx {
namespace ghost {

using sph::Index;

namespace {

using Vec3d = openvdb::math::Vec3<double>;

/// [IAGT12] Eq. 3: I clamped between lo and hi, mapped to [0, 1].
double clampPotential(double value, double lo, double hi)
{
    return (std::min(value, hi) - std::min(value, lo)) / (hi - lo);
}

/// Two unit vectors normal to the unit vector a.
void basisAround(const Vec3d& a, Vec3d& e1, Vec3d& e2)
{
    const Vec3d helper = std::abs(a[0]) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
    e1 = a.cross(helper);
    e1.normalize();
    e2 = a.cross(e1);
}

} // namespace

namespace {

using Row = sph::SettingSpec<WhitewaterSettings>;
using W = WhitewaterSettings;

std::vector<Row> whitewaterRows()
{
    using sph::between;
    using sph::nonNegative;
    using sph::positive;
    return {
        Row::number("trapped_air_min", "trappedAirMin", &W::trappedAirMin, nonNegative(), "m/s",
                    "trapped-air potential: relative speed of neighbours where it starts"),
        Row::number("trapped_air_max", "trappedAirMax", &W::trappedAirMax, positive(), "m/s",
                    "trapped-air potential: relative speed where it is full"),
        Row::number("wave_crest_min", "waveCrestMin", &W::waveCrestMin, nonNegative(), "1/m",
                    "wave-crest potential: surface curvature where it starts"),
        Row::number("wave_crest_max", "waveCrestMax", &W::waveCrestMax, positive(), "1/m",
                    "wave-crest potential: surface curvature where it is full"),
        Row::number("wave_crest_speed", "waveCrestSpeed", &W::waveCrestSpeed, nonNegative(), "m/s",
                    "a crest moves out of the liquid at least this fast"),
        Row::number("energy_min", "energyMin", &W::energyMin, nonNegative(), "J/kg",
                    "kinetic-energy potential: |v|^2 / 2 where it starts"),
        Row::number("energy_max", "energyMax", &W::energyMax, positive(), "J/kg",
                    "kinetic-energy potential: |v|^2 / 2 where it is full"),
        Row::number("trapped_air_rate", "trappedAirRate", &W::trappedAirRate, nonNegative(),
                    "1/(m^3 s)", "particles per m^3 of liquid per second at full trapped air"),
        Row::number("wave_crest_rate", "waveCrestRate", &W::waveCrestRate, nonNegative(),
                    "1/(m^3 s)", "particles per m^3 of liquid per second on full crests"),
        Row::number("spray_below", "sprayBelow", &W::sprayBelow, between(0, 1), "",
                    "liquid fraction below which a particle is spray"),
        Row::number("bubble_above", "bubbleAbove", &W::bubbleAbove, between(0, 1), "",
                    "liquid fraction above which a particle is a bubble"),
        Row::number("spray_drag", "sprayDrag", &W::sprayDrag, nonNegative(), "1/s",
                    "spray's drag towards still air"),
        Row::number("bubble_buoyancy", "bubbleBuoyancy", &W::bubbleBuoyancy, nonNegative(), "g",
                    "a bubble's buoyancy as a multiple of -gravity"),
        Row::number("bubble_drag", "bubbleDrag", &W::bubbleDrag, nonNegative(), "1/s",
                    "a bubble's drag towards the liquid's velocity"),
        Row::number("foam_lifetime_min", "foamLifetimeMin", &W::foamLifetimeMin, nonNegative(),
                    "s", "shortest foam lifetime"),
        Row::number("foam_lifetime_max", "foamLifetimeMax", &W::foamLifetimeMax, positive(), "s",
                    "longest foam lifetime"),
        Row::seed("seed", "seed", &W::seed, "random seed of the whitewater made"),
    };
}

} // namespace

const sph::SettingTable<WhitewaterSettings>& whitewaterSettingTable()
{
    static const sph::SettingTable<WhitewaterSettings> table{"whitewater setting",
                                                             whitewaterRows()};
    return table;
}

void WhitewaterSettings::validate() const
{
    sph::validateTable(whitewaterSettingTable(), *this);
    const sph::SettingCheck check("whitewater setting");
    // Each maximum above its minimum: {max's field, min's field, max, min}.
    const std::tuple<const char*, const char*, Real, Real> pairs[] = {
        {"trappedAirMax", "trappedAirMin", trappedAirMax, trappedAirMin},
        {"waveCrestMax", "waveCrestMin", waveCrestMax, waveCrestMin},
        {"energyMax", "energyMin", energyMax, energyMin},
        {"foamLifetimeMax", "foamLifetimeMin", foamLifetimeMax, foamLifetimeMin},
        {"bubbleAbove", "sprayBelow", bubbleAbove, sprayBelow}};
    for (const auto& [high, low, hi, lo] : pairs) {
        check.require(hi > lo, high, hi, msg("a number above ", low, " (", lo, ")").c_str());
    }
}

LiquidSnapshot LiquidSnapshot::fromParticles(const sph::ParticleSet& particles, Real spacing,
                                             Real supportFactor, const Vec3& gravity)
{
    auto rounded = [](const Vec3& a) {
        return Vec3(Real(float(a[0])), Real(float(a[1])), Real(float(a[2])));
    };
    LiquidSnapshot s;
    s.spacing = spacing;
    s.supportFactor = supportFactor;
    s.gravity = gravity;
    for (std::size_t i = 0; i < particles.size(); ++i) {
        if (particles.kinds()[i] != sph::ParticleKind::Liquid) continue;
        s.positions.push_back(rounded(particles.positions()[i]));
        s.velocities.push_back(rounded(particles.velocities()[i]));
        s.ids.push_back(particles.ids()[i]);
    }
    return s;
}

/// The liquid sorted by id, its neighbour grid, and each liquid particle's outward unit normal
/// (zero away from the surface) and the liquid's sums at any point.
struct Whitewater::Field
{
    explicit Field(const LiquidSnapshot& liquid)
        : h(double(liquid.spacing))
        , support(liquid.spacing * liquid.supportFactor)
        , kernel(support)
        , grid(support)
        , gravity(liquid.gravity)
    {
        std::vector<std::size_t> order(liquid.ids.size());
        std::iota(order.begin(), order.end(), std::size_t(0));
        std::sort(order.begin(), order.end(),
                  [&](std::size_t a, std::size_t b) { return liquid.ids[a] < liquid.ids[b]; });
        for (std::size_t k : order) {
            x.push_back(liquid.positions[k]);
            v.push_back(liquid.velocities[k]);
            ids.push_back(liquid.ids[k]);
        }
        grid.build(x);
        normals();
    }

    /// Liquid fraction c and kernel-weighted mean liquid velocity at p.
    void sample(const Vec3& p, double& c, Vec3d& velocity) const
    {
        double w = 0;
        Vec3d sum(0.0);
        grid.forEachInRadius(p, support, [&](Index j, const Vec3&, Real r) {
            const double wj = double(kernel.W(r));
            w += wj;
            sum += Vec3d(v[j]) * wj;
        });
        c = w * h * h * h;
        velocity = w > 0 ? sum / w : Vec3d(0.0);
    }

    double h;
    Real support;
    sph::CubicSplineKernel kernel;
    sph::NeighborGrid grid;
    Vec3 gravity;
    std::vector<Vec3> x, v;
    std::vector<sph::ParticleId> ids;
    std::vector<Vec3d> normal; ///< outward unit normal of a surface particle, else 0

private:
    void normals()
    {
        // The colour gradient sum_j V_j grad W_ij points into the liquid; at the surface its
        // length is about 1 / h, inside it is about 0 (SurfaceTension.h uses the same field).
        const double volume = h * h * h;
        normal.assign(x.size(), Vec3d(0.0));
        parallel::forEach(0, x.size(), [&](std::size_t i) {
            Vec3d gradient(0.0);
            grid.forEachInRadius(x[i], support, [&](Index, const Vec3& xij, Real r) {
                if (r > Real(0)) gradient += Vec3d(xij) * (volume * double(kernel.gradFactor(r)));
            });
            if (gradient.length() * h > 0.3) normal[i] = -gradient / gradient.length();
        });
    }
};

Whitewater::Whitewater(const WhitewaterSettings& settings) : mSettings(settings)
{
    mSettings.validate();
}

std::size_t Whitewater::count(WhitewaterType type) const
{
    return std::size_t(std::count(mTypes.begin(), mTypes.end(), type));
}

void Whitewater::step(const LiquidSnapshot& liquid, Real dt)
{
    if (liquid.positions.size() != liquid.velocities.size()
        || liquid.positions.size() != liquid.ids.size()) {
        throw ValueError("whitewater: the liquid's positions, velocities and ids differ in count");
    }
    const Field field(liquid);
    advect(field, dt);
    generate(field, dt);
    remove();
    classify(field);
    ++mGeneration;
}

sph::SolverState Whitewater::saveState() const
{
    sph::SolverState state;
    state.solver = "whitewater";
    sph::ParticleSet& p = state.particles;
    for (std::size_t k = 0; k < mPositions.size(); ++k)
        p.add(mPositions[k], mVelocities[k], Real(0), sph::ParticleKind::Liquid);
    p.ids() = mIds;
    p.setNextId(mNextId);
    std::vector<Real>& types = p.addScalarChannel("type");
    for (std::size_t k = 0; k < mTypes.size(); ++k) types[k] = Real(int(mTypes[k]));
    p.addScalarChannel("age") = mAges;
    p.addScalarChannel("life") = mLives;
    state.integers["generation"] = std::int64_t(mGeneration);
    return state;
}

void Whitewater::restoreState(const sph::SolverState& state)
{
    if (state.solver != "whitewater") {
        throw ValueError(msg("whitewater: cannot continue from a '", state.solver, "' state"));
    }
    const sph::ParticleSet& p = state.particles;
    for (const char* channel : {"type", "age", "life"}) {
        if (!p.hasScalarChannel(channel)) {
            throw ValueError(msg("whitewater state: no particle channel '", channel, "'"));
        }
    }
    mGeneration = std::uint64_t(state.count("generation"));
    mNextId = p.nextId();
    mPositions = p.positions();
    mVelocities = p.velocities();
    mIds = p.ids();
    mTypes.clear();
    for (Real t : p.scalarChannel("type")) {
        if (!(t == Real(0) || t == Real(1) || t == Real(2)))
            throw ValueError(msg("whitewater state: particle type ", t, ": expected 0, 1 or 2"));
        mTypes.push_back(WhitewaterType(int(t)));
    }
    mAges = p.scalarChannel("age");
    mLives = p.scalarChannel("life");
}

void Whitewater::advect(const Field& field, Real dt)
{
    const WhitewaterSettings& s = mSettings;
    const Vec3d g(field.gravity);
    parallel::forEach(0, mPositions.size(), [&](std::size_t k) {
        double c;
        Vec3d liquid;
        field.sample(mPositions[k], c, liquid);
        Vec3d v(mVelocities[k]);
        switch (mTypes[k]) {
        case WhitewaterType::Spray:
            // Semi-implicit: gravity, and the drag towards still air.
            v = (v + g * double(dt)) / (1.0 + double(s.sprayDrag) * double(dt));
            break;
        case WhitewaterType::Foam:
            v = liquid;
            mLives[k] -= dt;
            break;
        case WhitewaterType::Bubble:
            v = (v + (-double(s.bubbleBuoyancy) * g + double(s.bubbleDrag) * liquid) * double(dt))
                / (1.0 + double(s.bubbleDrag) * double(dt));
            break;
        }
        mVelocities[k] = Vec3(v);
        const Vec3 from = mPositions[k];
        mPositions[k] += Vec3(v * double(dt));
        mAges[k] += dt;
        if (crossesSolid(from, mPositions[k], field.h))
            mLives[k] = -std::numeric_limits<Real>::infinity();
    });
}

bool Whitewater::crossesSolid(const Vec3& from, const Vec3& to, double h) const
{
    if (!mSolidPhi) return false;
    // Samples at most h / 2 apart along the path: a spray particle covers 10 cm in a frame at
    // 3 m/s, and would otherwise pass through a wall thinner than that.
    const double length = double((to - from).length());
    const int samples = int(std::ceil(length / (0.5 * h)));
    for (int s = 1; s < samples; ++s) {
        const Real t = Real(double(s) / double(samples));
        if (mSolidPhi(from + (to - from) * t) < Real(0)) return true;
    }
    return false;
}

void Whitewater::remove()
{
    std::size_t kept = 0;
    for (std::size_t k = 0; k < mPositions.size(); ++k) {
        const Vec3& p = mPositions[k];
        // A life of -infinity: the particle's path went through a solid (advect).
        const bool gone = (mTypes[k] == WhitewaterType::Foam && mLives[k] <= Real(0))
                          || mLives[k] == -std::numeric_limits<Real>::infinity()
                          || (!mKillBox.empty() && !mKillBox.contains(p))
                          || (mSolidPhi && mSolidPhi(p) < Real(0));
        if (gone) continue;
        mPositions[kept] = p;
        mVelocities[kept] = mVelocities[k];
        mIds[kept] = mIds[k];
        mTypes[kept] = mTypes[k];
        mAges[kept] = mAges[k];
        mLives[kept] = mLives[k];
        ++kept;
    }
    for (auto* a : {&mPositions, &mVelocities}) a->resize(kept);
    mIds.resize(kept);
    mTypes.resize(kept);
    mAges.resize(kept);
    mLives.resize(kept);
}

void Whitewater::classify(const Field& field)
{
    parallel::forEach(0, mPositions.size(), [&](std::size_t k) {
        double c;
        Vec3d liquid;
        field.sample(mPositions[k], c, liquid);
        mTypes[k] = c < double(mSettings.sprayBelow)    ? WhitewaterType::Spray
                    : c > double(mSettings.bubbleAbove) ? WhitewaterType::Bubble
                                                        : WhitewaterType::Foam;
    });
}

void Whitewater::generate(const Field& field, Real dt)
{
    // Each liquid particle's count (its potentials), then the particles in id order.
    const WhitewaterSettings& s = mSettings;
    const std::size_t n = field.x.size();
    const double H = double(field.support), volume = field.h * field.h * field.h;
    std::vector<double> expected(n, 0.0);
    parallel::forEach(0, n, [&](std::size_t i) {
        const Vec3d vi(field.v[i]);
        const double energy = clampPotential(0.5 * vi.lengthSqr(), s.energyMin, s.energyMax);
        if (energy <= 0) return;
        double weights = 0, trapped = 0, divergence = 0, moment = 0;
        Vec3d mean(0.0);
        field.grid.forEachInRadius(field.x[i], field.support, [&](Index j, const Vec3& xij, Real r) {
            const double w = 1 - double(r) / H;
            weights += w;
            mean += Vec3d(field.v[j]) * w;
            if (j == Index(i)) return;
            const Vec3d x(xij), vij = vi - Vec3d(field.v[j]);
            const double speed = vij.length();
            if (speed > 0) trapped += speed * (1 - vij.dot(x) / (speed * double(r))) * w;
            // The curvature over the neighbours with a normal of their own (the surface's).
            if (field.normal[j].lengthSqr() == 0) return;
            const double f = volume * double(field.kernel.gradFactor(r));
            divergence += (field.normal[j] - field.normal[i]).dot(x) * f;
            moment -= x.lengthSqr() * f;
        });
        const double ta = clampPotential(trapped / weights, s.trappedAirMin, s.trappedAirMax);
        double wc = 0;
        const Vec3d relative = vi - mean / weights;
        const double rise = relative.dot(field.normal[i]);
        if (field.normal[i].lengthSqr() > 0 && rise >= double(s.waveCrestSpeed)
            && rise >= 0.6 * relative.length() && moment > 0) {
            // div n^ over the neighbours, renormalised by the kernel's first moment over them
            // (3 for a whole neighbourhood).
            wc = clampPotential(3 * divergence / moment, s.waveCrestMin, s.waveCrestMax);
        }
        expected[i] = volume * energy
                      * (double(s.trappedAirRate) * ta + double(s.waveCrestRate) * wc) * double(dt);
    });
    for (std::size_t i = 0; i < n; ++i) {
        if (expected[i] <= 0) continue;
        sph::Rng rng(s.seed ^ (0x9e3779b97f4a7c15ULL * (mGeneration + 1)),
                     std::uint64_t(field.ids[i]));
        const double whole = std::floor(expected[i]);
        const std::size_t count = std::size_t(whole) + (rng.uniform01() < expected[i] - whole);
        if (count) emit(field, i, count, dt);
    }
}

void Whitewater::emit(const Field& field, std::size_t i, std::size_t count, Real dt)
{
    // [IAGT12] Sec. 4.4: uniform in a cylinder of radius h / 2 around x_i along v_i, as long
    // as the particle moves in dt.
    sph::Rng rng(mSettings.seed ^ (0xbf58476d1ce4e5b9ULL * (mGeneration + 1)),
                 std::uint64_t(field.ids[i]));
    const Vec3d x(field.x[i]), v(field.v[i]);
    const double speed = v.length();
    Vec3d axis = speed > 0 ? v / speed : Vec3d(0, 1, 0), e1, e2;
    basisAround(axis, e1, e2);
    const double span = mSettings.foamLifetimeMax - mSettings.foamLifetimeMin;
    for (std::size_t k = 0; k < count; ++k) {
        const double r = 0.5 * field.h * std::sqrt(rng.uniform01());
        const double theta = 2 * M_PI * rng.uniform01();
        const double along = rng.uniform01() * speed * double(dt);
        const Vec3d p = x + e1 * (r * std::cos(theta)) + e2 * (r * std::sin(theta)) + axis * along;
        mPositions.push_back(Vec3(p));
        mVelocities.push_back(field.v[i]);
        mIds.push_back(mNextId++);
        mTypes.push_back(WhitewaterType::Spray);
        mAges.push_back(Real(0));
        mLives.push_back(Real(mSettings.foamLifetimeMin + span * rng.uniform01()));
    }
}

} // namespace ghost
} // namespace ghostfx
