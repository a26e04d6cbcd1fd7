/// @file   SplitMerge.cc
/// @brief  Pattern splitting and decentration-ordered merging with re-splitting ([RYY15]
///         Sec. 4.1-4.2, Eqs. 19-20, Fig. 3).
#include "ghostfx/gas/SplitMerge.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <tuple>

namespace ghostfx {
namespace gas {

namespace {

/// A particle to append: built-ins plus one value per named channel (in name order).
struct NewParticle
{
    Vec3d x{0.0}, v{0.0};
    double m = 0.0;
    ParticleKind kind = ParticleKind::Liquid;
    double density = 0.0, pressure = 0.0;
    std::vector<double> scalars; ///< ordered as particles.scalarChannelNames()
    std::vector<Vec3d> vectors;  ///< ordered as particles.vectorChannelNames()
};

/// Named channels of a set, fetched once (references stay valid until the set grows).
struct Channels
{
    std::vector<std::string> scalarNames, vectorNames;
    std::size_t hSlot = 0, splitSlot = 0;

    explicit Channels(const ParticleSet& p)
        : scalarNames(p.scalarChannelNames())
        , vectorNames(p.vectorChannelNames())
    {
        hSlot = slotOf(SMOOTHING_RADIUS_CHANNEL);
        splitSlot = slotOf(SPLIT_COUNT_CHANNEL);
    }
    std::size_t slotOf(const std::string& name) const
    {
        return std::size_t(std::find(scalarNames.begin(), scalarNames.end(), name)
                           - scalarNames.begin());
    }
};

/// Every channel value of particle i, as a NewParticle.
NewParticle copyOf(const ParticleSet& p, const Channels& ch, Index i)
{
    NewParticle n;
    n.x = Vec3d(p.positions()[i]);
    n.v = Vec3d(p.velocities()[i]);
    n.m = double(p.masses()[i]);
    n.kind = p.kinds()[i];
    n.density = double(p.densities()[i]);
    n.pressure = double(p.pressures()[i]);
    for (const auto& name : ch.scalarNames) n.scalars.push_back(double(p.scalarChannel(name)[i]));
    for (const auto& name : ch.vectorNames) n.vectors.push_back(Vec3d(p.vectorChannel(name)[i]));
    return n;
}

/// Daughters of `mother` by `pattern`. Masses are rounded to Real here and the rounding residual
/// of their sum is moved onto the heaviest daughter, so sum(Real masses) equals the mother's mass
/// to one rounding.
void appendDaughters(const NewParticle& mother, const Channels& ch, const SplitPattern& pattern,
                     const SplitOptions& options, std::vector<NewParticle>& out)
{
    const double h = mother.scalars[ch.hSlot];
    const std::size_t c = pattern.childCount();
    const std::size_t centre = pattern.centreIndex();
    const std::size_t first = out.size();
    std::size_t heaviest = 0;
    for (std::size_t k = 0; k < c; ++k) {
        if (pattern.lambda[k] > pattern.lambda[heaviest]) heaviest = k;
    }
    double others = 0.0;
    for (std::size_t k = 0; k < c; ++k) {
        NewParticle d = mother;
        d.x = mother.x + pattern.offsets[k] * (pattern.epsilon * h);
        d.m = double(Real(pattern.lambda[k] * mother.m));
        if (k != heaviest) others += d.m;
        d.scalars[ch.hSlot] = pattern.alpha * h;
        if (ch.splitSlot < d.scalars.size() && options.countSplit) d.scalars[ch.splitSlot] += 1.0;
        const auto& kind = k == centre ? options.centreKind : options.outerKind;
        if (kind) d.kind = *kind;
        out.push_back(std::move(d));
    }
    out[first + heaviest].m = double(Real(mother.m - others));
}

/// Append `news` to the set (new ids), then remove the particles flagged in `remove`.
void commit(ParticleSet& p, const Channels& ch, const std::vector<NewParticle>& news,
            std::vector<std::uint8_t> remove)
{
    const std::size_t n0 = p.size();
    p.reserve(n0 + news.size());
    for (const auto& n : news) p.add(sph::toVec3(n.x), sph::toVec3(n.v), Real(n.m), n.kind);
    for (std::size_t s = 0; s < ch.scalarNames.size(); ++s) {
        auto& data = p.scalarChannel(ch.scalarNames[s]);
        for (std::size_t k = 0; k < news.size(); ++k) data[n0 + k] = Real(news[k].scalars[s]);
    }
    for (std::size_t s = 0; s < ch.vectorNames.size(); ++s) {
        auto& data = p.vectorChannel(ch.vectorNames[s]);
        for (std::size_t k = 0; k < news.size(); ++k)
            data[n0 + k] = sph::toVec3(news[k].vectors[s]);
    }
    for (std::size_t k = 0; k < news.size(); ++k) {
        p.densities()[n0 + k] = Real(news[k].density);
        p.pressures()[n0 + k] = Real(news[k].pressure);
    }
    remove.resize(p.size(), 0);
    p.removeIf(remove);
}

void checkPattern(const SplitPattern& pattern)
{
    if (pattern.childCount() == 0 || pattern.lambda.size() != pattern.childCount()) {
        throw ValueError(msg("split pattern '", pattern.name, "' has ", pattern.childCount(),
                             " offsets and ", pattern.lambda.size(),
                             " mass ratios: expected the same number, >= 1"));
    }
    if (!(pattern.epsilon > 0.0) || !(pattern.alpha > 0.0)) {
        throw ValueError(msg("split pattern '", pattern.name, "': epsilon = ", pattern.epsilon,
                             ", alpha = ", pattern.alpha, ": expected both > 0"));
    }
}

} // namespace

std::vector<Real>& addSplitChannels(ParticleSet& particles, Real smoothingRadius)
{
    if (!(smoothingRadius > Real(0)) || !std::isfinite(smoothingRadius)) {
        throw ValueError(
            msg("smoothing radius = ", smoothingRadius, " m: expected a finite value > 0"));
    }
    particles.addScalarChannel(SPLIT_COUNT_CHANNEL, Real(0));
    return particles.addScalarChannel(SMOOTHING_RADIUS_CHANNEL, smoothingRadius);
}

Index splitParticles(ParticleSet& particles, const std::vector<Index>& which,
                     const SplitPattern& pattern, const SplitOptions& options)
{
    checkPattern(pattern);
    if (!particles.hasScalarChannel(SMOOTHING_RADIUS_CHANNEL)) {
        throw ValueError(msg("splitParticles: the particle set has no '", SMOOTHING_RADIUS_CHANNEL,
                             "' (smoothing radius) channel: call addSplitChannels first"));
    }
    const std::size_t n = particles.size();
    std::vector<std::uint8_t> remove(n, 0);
    const auto& h = particles.scalarChannel(SMOOTHING_RADIUS_CHANNEL);
    for (Index i : which) {
        if (i >= n || remove[i]) {
            throw ValueError(msg("splitParticles: index ", i,
                                 " is out of range or repeated: "
                                 "expected distinct indices below ",
                                 n));
        }
        if (!(h[i] > Real(0)) || !std::isfinite(h[i])) {
            throw ValueError(msg("splitParticles: particle ", i, " (id ", particles.ids()[i],
                                 ") has smoothing radius h = ", h[i], ": expected > 0"));
        }
        remove[i] = 1;
    }
    const Channels ch(particles);
    std::vector<NewParticle> news;
    news.reserve(which.size() * pattern.childCount());
    for (Index i : which) appendDaughters(copyOf(particles, ch, i), ch, pattern, options, news);
    commit(particles, ch, news, std::move(remove));
    return Index(n - which.size());
}

Index splitParticle(ParticleSet& particles, Index i, const SplitPattern& pattern,
                    const SplitOptions& options)
{
    return splitParticles(particles, std::vector<Index>{i}, pattern, options);
}

// ---------------------------------------------------------------------------------------------
// [RYY15] Eqs. 19-20

std::array<double, 9> inertiaMatrix(const ParticleSet& particles, const Vec3& xM,
                                    const std::vector<Index>& group)
{
    double Ixx = 0, Iyy = 0, Izz = 0, Ixy = 0, Iyz = 0, Ixz = 0;
    for (Index j : group) {
        const double m = double(particles.masses()[j]);
        const Vec3d r = Vec3d(particles.positions()[j]) - Vec3d(xM);
        Ixx += m * (r[1] * r[1] + r[2] * r[2]);
        Iyy += m * (r[0] * r[0] + r[2] * r[2]);
        Izz += m * (r[0] * r[0] + r[1] * r[1]);
        Ixy += m * r[0] * r[1];
        Iyz += m * r[1] * r[2];
        Ixz += m * r[0] * r[2];
    }
    return {Ixx, -Ixy, -Ixz, -Ixy, Iyy, -Iyz, -Ixz, -Iyz, Izz};
}

double massDecentration(const std::array<double, 9>& I)
{
    const double tr3 = (I[0] + I[4] + I[8]) / 3.0;
    const double det = I[0] * (I[4] * I[8] - I[5] * I[7]) - I[1] * (I[3] * I[8] - I[5] * I[6])
                       + I[2] * (I[3] * I[7] - I[4] * I[6]);
    return std::abs(tr3 * tr3 * tr3 - det);
}

// ---------------------------------------------------------------------------------------------

const SplitPattern& defaultResplitPattern()
{
    static const SplitPattern pattern = [] {
        const double alpha = std::cbrt(1.0 / 12.0);
        const double eps = bestEpsilon(PatternShape::Icosahedron, alpha, 0.1, 0.9);
        SplitPattern p = cachedPattern(PatternShape::Icosahedron, eps, alpha);
        p.name = "icosahedron (resplit)";
        return p;
    }();
    return pattern;
}

void MergeSettings::validate() const
{
    if (splitThreshold < 1) {
        throw ValueError(msg("merge.splitThreshold = ", splitThreshold, ": expected >= 1"));
    }
    if (!(neighbourhoodFactor > Real(0)) || !std::isfinite(neighbourhoodFactor)) {
        throw ValueError(msg("merge.neighbourhoodFactor = ", neighbourhoodFactor,
                             ": expected a finite value > 0"));
    }
    if (!(maxSizeRatio >= Real(1))) {
        throw ValueError(msg("merge.maxSizeRatio = ", maxSizeRatio, ": expected >= 1"));
    }
    if (minMerged == 1) throw ValueError("merge.minMerged = 1: expected 0 (full groups) or >= 2");
    if (maxMerged == 1)
        throw ValueError("merge.maxMerged = 1: expected 0 (re-split count) or >= 2");
    if (minMerged != 0 && minMerged > groupLimit()) {
        throw ValueError(msg("merge.minMerged = ", minMerged,
                             ": expected at most the group limit (", groupLimit(), ")"));
    }
    if (sizeRule == MergeSizeRule::ReferenceDensity
        && (!(referenceMass > Real(0)) || !(referenceRadius > Real(0)))) {
        throw ValueError(msg("merge.referenceMass = ", referenceMass,
                             " kg, referenceRadius = ", referenceRadius,
                             " m: expected both > 0 with sizeRule "
                             "ReferenceDensity"));
    }
    if (resplitPattern) checkPattern(*resplitPattern);
}

const SplitPattern& MergeSettings::pattern() const
{
    return resplitPattern ? *resplitPattern : defaultResplitPattern();
}

std::size_t MergeSettings::groupLimit() const
{
    if (maxMerged != 0) return maxMerged;
    return resplit ? pattern().childCount() : 12;
}

std::size_t MergeSettings::groupMinimum() const
{
    return minMerged == 0 ? groupLimit() : minMerged;
}

std::vector<MergeGroup> planMerges(const ParticleSet& particles, const sph::NeighborGrid& grid,
                                   const MergeSettings& settings)
{
    settings.validate();
    std::vector<MergeGroup> plan;
    if (!particles.hasScalarChannel(SPLIT_COUNT_CHANNEL) || particles.empty()) return plan;
    if (!particles.hasScalarChannel(SMOOTHING_RADIUS_CHANNEL)) {
        throw ValueError(msg("mergeParticles: the particle set has no '", SMOOTHING_RADIUS_CHANNEL,
                             "' (smoothing radius) channel: call addSplitChannels first"));
    }
    if (grid.size() != particles.size()) {
        throw ValueError(msg("mergeParticles: neighbour grid holds ", grid.size(),
                             " particles, the set ", particles.size(),
                             ": rebuild the grid on the current positions"));
    }
    const auto& splits = particles.scalarChannel(SPLIT_COUNT_CHANNEL);
    const auto& h = particles.scalarChannel(SMOOTHING_RADIUS_CHANNEL);
    const auto& x = particles.positions();
    const auto& kinds = particles.kinds();
    const auto& ids = particles.ids();

    std::vector<Index> candidates;
    for (std::size_t i = 0; i < particles.size(); ++i) {
        if (settings.candidateKind && kinds[i] != *settings.candidateKind) continue;
        if (splits[i] >= Real(settings.splitThreshold)) candidates.push_back(Index(i));
    }
    const std::size_t limit = settings.groupLimit();

    // Gather per candidate (each writes only its own group): the nearest similar neighbours
    // within the neighbourhood radius, and the decentration of that group (Eqs. 19-20).
    std::vector<MergeGroup> groups(candidates.size());
    parallel::forEach(
        0, candidates.size(),
        [&](std::size_t c) {
        const Index M = candidates[c];
        const Real radius = settings.neighbourhoodFactor * h[M];
        std::vector<std::tuple<Real, sph::ParticleId, Index>> near;
        grid.forEachInRadius(x[M], radius, [&](Index j, const Vec3&, Real r) {
            if (j == M || kinds[j] != kinds[M]) return;
            const Real ratio = h[j] / h[M];
            if (ratio > settings.maxSizeRatio || ratio * settings.maxSizeRatio < Real(1)) return;
            near.emplace_back(r, ids[j], j);
        });
        std::sort(near.begin(), near.end());
        MergeGroup& g = groups[c];
        g.candidate = M;
        g.members.push_back(M);
        for (const auto& t : near) {
            if (g.members.size() >= limit) break;
            g.members.push_back(std::get<2>(t));
        }
        g.eta = massDecentration(inertiaMatrix(particles, x[M], g.members));
        },
        16);

    std::vector<std::size_t> order(groups.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        if (groups[a].eta != groups[b].eta) return groups[a].eta < groups[b].eta;
        return ids[groups[a].candidate] < ids[groups[b].candidate];
    });
    std::vector<std::uint8_t> used(particles.size(), 0);
    for (std::size_t c : order) {
        MergeGroup& g = groups[c];
        if (g.members.size() < settings.groupMinimum()) continue;
        bool free = true;
        for (Index j : g.members) free = free && !used[j];
        if (!free) continue;
        for (Index j : g.members) used[j] = 1;
        plan.push_back(std::move(g));
        if (settings.maxMergesPerCall != 0 && plan.size() >= settings.maxMergesPerCall) break;
    }
    return plan;
}

MergeResult applyMerges(ParticleSet& particles, const std::vector<MergeGroup>& plan,
                        const MergeSettings& settings)
{
    settings.validate();
    MergeResult result;
    if (plan.empty()) return result;
    const Channels ch(particles);
    if (ch.hSlot >= ch.scalarNames.size()) {
        throw ValueError(msg("applyMerges: the particle set has no '", SMOOTHING_RADIUS_CHANNEL,
                             "' (smoothing radius) channel: call addSplitChannels first"));
    }
    std::vector<std::uint8_t> remove(particles.size(), 0);
    std::vector<NewParticle> news;
    SplitOptions keepKinds;
    keepKinds.countSplit = false;
    for (const MergeGroup& g : plan) {
        // M' ([RYY15] Fig. 3b): mass and momentum of the group, mass-weighted means of the
        // other channels, position and size by the settings' rules.
        NewParticle merged = copyOf(particles, ch, g.candidate);
        double mass = 0.0, h3 = 0.0;
        Vec3d momentum(0.0), moment(0.0);
        std::vector<double> scalarSum(ch.scalarNames.size(), 0.0);
        std::vector<Vec3d> vectorSum(ch.vectorNames.size(), Vec3d(0.0));
        double rhoSum = 0.0, pSum = 0.0;
        for (Index j : g.members) {
            if (remove[j]) {
                throw ValueError(msg("applyMerges: particle ", j, " is in two merge groups"));
            }
            remove[j] = 1;
            const NewParticle pj = copyOf(particles, ch, j);
            mass += pj.m;
            momentum += pj.v * pj.m;
            moment += pj.x * pj.m;
            h3 += pj.scalars[ch.hSlot] * pj.scalars[ch.hSlot] * pj.scalars[ch.hSlot];
            rhoSum += pj.m * pj.density;
            pSum += pj.m * pj.pressure;
            for (std::size_t s = 0; s < scalarSum.size(); ++s) scalarSum[s] += pj.m * pj.scalars[s];
            for (std::size_t s = 0; s < vectorSum.size(); ++s) vectorSum[s] += pj.vectors[s] * pj.m;
        }
        if (!(mass > 0.0)) {
            throw NumericalError(msg("applyMerges: group of particle id ",
                                     particles.ids()[g.candidate], " has total mass ", mass,
                                     " kg: expected > 0"));
        }
        merged.m = mass;
        merged.v = momentum / mass;
        if (settings.placement == MergePlacement::CentreOfMass) merged.x = moment / mass;
        merged.density = rhoSum / mass;
        merged.pressure = pSum / mass;
        for (std::size_t s = 0; s < scalarSum.size(); ++s) merged.scalars[s] = scalarSum[s] / mass;
        for (std::size_t s = 0; s < vectorSum.size(); ++s) merged.vectors[s] = vectorSum[s] / mass;
        merged.scalars[ch.hSlot] = settings.sizeRule == MergeSizeRule::VolumeSum
                                       ? std::cbrt(h3)
                                       : double(settings.referenceRadius)
                                             * std::cbrt(mass / double(settings.referenceMass));
        if (ch.splitSlot < merged.scalars.size()) merged.scalars[ch.splitSlot] = 0.0;

        ++result.merges;
        result.removed += g.members.size();
        if (settings.resplit) {
            // Fig. 3c: split M' into daughters of the desired size, counters reset.
            const std::size_t before = news.size();
            appendDaughters(merged, ch, settings.pattern(), keepKinds, news);
            result.added += news.size() - before;
        } else {
            merged.m = double(Real(merged.m));
            news.push_back(std::move(merged));
            ++result.added;
        }
    }
    commit(particles, ch, news, std::move(remove));
    return result;
}

MergeResult mergeParticles(ParticleSet& particles, const sph::NeighborGrid& grid,
                           const MergeSettings& settings)
{
    return applyMerges(particles, planMerges(particles, grid, settings), settings);
}

} // namespace gas
} // namespace ghostfx
