/// @file   GasEmission.cc
/// @brief  The gas solver's sources: adding a source, and the emission step (air converted in the
///         ambient baseline, new gas grown in the free room, the gas inside held at the source's
///         temperature).
#include "ghostfx/gas/GasSolver.h"

#include "GasSource.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/PoissonSampler.h>

#include <cmath>
#include <limits>

namespace ghostfx {
namespace gas {

using namespace sph;

void GasSolver::addSource(const LevelSet& shape, const GasSource& source)
{
    if (!isFinite(source.velocity) || !std::isfinite(source.temperature)) {
        throw ValueError(msg("gas source '", shape.name(),
                             "': velocity and temperature must be "
                             "finite"));
    }
    if (!(source.rate >= Real(0)) || !std::isfinite(source.rate)) {
        throw ValueError(msg("gas source '", shape.name(), "': rate = ", source.rate,
                             " particles/s: expected >= 0 (0 = fill the source)"));
    }
    if (!(source.end > source.start) || !(source.start >= 0)) {
        throw ValueError(msg("gas source '", shape.name(), "': start ", source.start, " s, end ",
                             source.end, " s: expected 0 <= start < end"));
    }
    auto s = std::make_unique<Source>(Source{shape, source, 0.0});
    const std::size_t k = mSources.size();
    if (k < mRestoredBudgets.size()) s->budget = mRestoredBudgets[k];
    mSources.push_back(std::move(s));
}

std::size_t GasSolver::Source::allowance(Real dt)
{
    // Rate-limited sources accumulate their allowance; 0 = no limit.
    if (!(params.rate > Real(0))) return std::numeric_limits<std::size_t>::max();
    budget += double(params.rate) * double(dt);
    return std::size_t(std::floor(budget));
}

void GasSolver::emit(Real dt)
{
    for (std::size_t e = 0; e < mSources.size(); ++e) {
        Source& src = *mSources[e];
        if (!src.active(mRun.time)) continue;
        const PlacedSource at(src, mRun.time);
        const std::size_t allowed = src.allowance(dt);
        std::size_t added = convertAmbientAir(at, allowed);
        added += addFreshGas(e, at, allowed - added);
        if (src.params.rate > Real(0)) src.budget -= double(added);
        mRun.emitted += added;
        heatSourceGas(at);
    }
}

std::size_t GasSolver::convertAmbientAir(const PlacedSource& at, std::size_t allowed)
{
    // The standard approach marks the air passing through the source as visible gas.
    if (mSettings.method != Method::Ambient) return 0;
    auto& ambient = mParticles.scalarChannel(channel::AMBIENT);
    std::size_t added = 0;
    for (std::size_t i = 0; i < mParticles.size() && added < allowed; ++i) {
        if (mParticles.kinds()[i] != ParticleKind::Gas || ambient[i] == Real(0)) continue;
        if (!at.contains(mParticles.positions()[i])) continue;
        ambient[i] = Real(0);
        mParticles.velocities()[i] = at.source.params.velocity;
        ++added;
    }
    return added;
}

std::size_t GasSolver::addFreshGas(std::size_t e, const PlacedSource& at, std::size_t room)
{
    // The free room in the source is filled with new gas, in every method, so the baseline
    // emits what the fast solver emits: its air, once converted, rises out of the source as the
    // fast solver's gas does, and the room it leaves is not always refilled by air in time (the
    // shipped plume's baseline stopped emitting at 143 particles).
    std::vector<Vec3> seeds, obstacles;
    const std::vector<Real>* air =
        mSettings.method == Method::Ambient ? &mParticles.scalarChannel(channel::AMBIENT) : nullptr;
    const Aabb near = at.box.padded(mSettings.supportRadius());
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        const Vec3& x = mParticles.positions()[i];
        if (!near.contains(x)) continue;
        const bool visible =
            mParticles.kinds()[i] == ParticleKind::Gas && !(air && (*air)[i] != Real(0));
        if (visible && at.contains(x)) {
            seeds.push_back(x);
        } else {
            obstacles.push_back(x);
        }
    }
    std::vector<Vec3> fresh =
        seeds.empty() ? fillSource(e, at, obstacles) : growFromSeeds(e, at, seeds, obstacles);
    if (fresh.size() > room) fresh.resize(room);
    if (!fresh.empty()) {
        const Index first = mParticles.addBatch(fresh, mMass, ParticleKind::Gas);
        for (std::size_t i = first; i < mParticles.size(); ++i) {
            mParticles.velocities()[i] = at.source.params.velocity;
        }
    }
    return fresh.size();
}

std::vector<Vec3> GasSolver::fillSource(std::size_t e, const PlacedSource& at,
                                        const std::vector<Vec3>& obstacles) const
{
    // Nothing to grow from: fill the source like a block of gas.
    const Real r = PoissonSettings::SB12_RADIUS_FACTOR * mSettings.spacing;
    NeighborGrid grid(r);
    grid.build(obstacles);
    std::vector<Vec3> fresh;
    for (const Vec3& xl :
         sampleShape(at.source.shape, mSettings.seed + 31337ULL * (e + 1) + mRun.step)) {
        const Vec3 x = at.xf.toWorld(xl);
        bool clear = !blockedBySolid(x);
        if (clear && !obstacles.empty()) {
            grid.forEachInRadius(x, r, [&](Index, const Vec3&, Real) { clear = false; });
        }
        if (clear) fresh.push_back(x);
    }
    return fresh;
}

std::vector<Vec3> GasSolver::growFromSeeds(std::size_t e, const PlacedSource& at,
                                           const std::vector<Vec3>& seeds,
                                           const std::vector<Vec3>& obstacles) const
{
    PoissonSettings ps = PoissonSettings::forSpacing(mSettings.spacing);
    ps.seed = mSettings.seed ^ (0xc2b2ae3d27d4eb4fULL * (mRun.step + 1) + e);
    // [SB12] Sec. 4.5.2: emission during the run takes 8 attempts per seed, not 30.
    ps.volumeAttempts = PoissonSettings::SB12_SEEDED_ATTEMPTS;
    auto accept = [&](const Vec3& x) { return at.inside(x) && !blockedBySolid(x); };
    return PoissonDiskSampler(ps).sampleFromSeeds(seeds, obstacles, accept, at.box);
}

void GasSolver::heatSourceGas(const PlacedSource& at)
{
    // The source is a heater: visible gas inside it is held at the source temperature.
    auto& T = mParticles.scalarChannel(channel::TEMPERATURE);
    const std::vector<Real>* ambient = mParticles.hasScalarChannel(channel::AMBIENT)
                                           ? &mParticles.scalarChannel(channel::AMBIENT)
                                           : nullptr;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::Gas) continue;
        if (ambient && (*ambient)[i] != Real(0)) continue;
        if (at.contains(mParticles.positions()[i])) T[i] = at.source.params.temperature;
    }
}

} // namespace gas
} // namespace ghostfx
