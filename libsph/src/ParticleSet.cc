/// @file   ParticleSet.cc
/// @brief  Structure-of-arrays particle storage.
#include "ghostfx/sph/ParticleSet.h"

#include "ghostfx/sph/EnumNames.h"
#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/Parallel.h"

#include <algorithm>
#include <type_traits>

namespace ghostfx {
namespace sph {

const char* kindName(ParticleKind kind)
{
    static const EnumName<ParticleKind> names[] = {{ParticleKind::Liquid, "liquid"},
                                                   {ParticleKind::GhostAir, "ghost_air"},
                                                   {ParticleKind::GhostSolid, "ghost_solid"},
                                                   {ParticleKind::Gas, "gas"},
                                                   {ParticleKind::Boundary, "boundary"}};
    return nameOf(names, kind);
}

namespace {

/// out[k] = in[order[k]], reusing `scratch` as the destination, then swapping.
template <typename T>
void permute(std::vector<T>& data, const std::vector<Index>& order, std::vector<T>& scratch)
{
    scratch.resize(data.size());
    parallel::forEach(
        0, order.size(), [&](std::size_t k) { scratch[k] = data[order[k]]; }, 4096);
    data.swap(scratch);
}

template <typename T>
void compact(std::vector<T>& data, const std::vector<std::uint8_t>& remove)
{
    std::size_t out = 0;
    for (std::size_t i = 0; i < data.size(); ++i) {
        if (!remove[i]) data[out++] = data[i];
    }
    data.resize(out);
}

std::string joinNames(const std::vector<std::string>& names)
{
    if (names.empty()) return "none";
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

/// The names of a channel map, in order.
template <typename Map>
std::vector<std::string> keysOf(const Map& channels)
{
    std::vector<std::string> names;
    for (const auto& entry : channels) names.push_back(entry.first);
    return names;
}

/// The channel `name` of `channels`; ValueError naming the `kind` ("scalar" or "vector")
/// channels that exist.
template <typename Map>
const typename Map::mapped_type& findChannel(const Map& channels, const std::string& name,
                                             const char* kind)
{
    const auto it = channels.find(name);
    if (it == channels.end()) {
        throw ValueError(msg("particle channel '", name, "' (", kind, ") does not exist; ", kind,
                             " channels: ", joinNames(keysOf(channels))));
    }
    return it->second;
}

} // namespace

template <typename Fn>
void ParticleSet::forEachChannel(Fn&& fn)
{
    fn(mPositions);
    fn(mVelocities);
    fn(mMasses);
    fn(mDensities);
    fn(mPressures);
    fn(mKinds);
    fn(mIds);
    for (auto& [name, ch] : mScalars) fn(ch.data);
    for (auto& [name, ch] : mVectors) fn(ch.data);
}

void ParticleSet::growFor(std::size_t count)
{
    // Room for `count` more, growing by a thirty-second rather than doubling: a solver appends
    // a few particles every step (emission, air), and doubling would leave up to half of every
    // channel unused (ParticleSet::memoryBytes counts capacity); an eighth left 12 % of the
    // paper-size double dam break's liquid set unused (bench/history/diary-2026-11.md). A copy of
    // the set every 3 % of growth costs little next to the steps in between.
    const std::size_t n = mPositions.size() + count;
    if (n <= mPositions.capacity()) return;
    const std::size_t grown = std::max(n, mPositions.size() + mPositions.size() / 32);
    forEachChannel([grown](auto& data) { data.reserve(grown); });
}

void ParticleSet::appendDefaults(std::size_t count)
{
    const std::size_t n = mPositions.size();
    mVelocities.resize(n, Vec3(0));
    mMasses.resize(n, Real(0));
    mDensities.resize(n, Real(0));
    mPressures.resize(n, Real(0));
    mKinds.resize(n, ParticleKind::Liquid);
    for (std::size_t k = 0; k < count; ++k) {
        mIds.push_back(mNextId);
        mNextId += mIdStride;
    }
    for (auto& [name, ch] : mScalars) ch.data.resize(n, ch.defaultValue);
    for (auto& [name, ch] : mVectors) ch.data.resize(n, ch.defaultValue);
}

Index ParticleSet::add(const Vec3& x, const Vec3& v, Real m, ParticleKind kind)
{
    const Index i = Index(mPositions.size());
    growFor(1);
    mPositions.push_back(x);
    appendDefaults(1);
    mVelocities[i] = v;
    mMasses[i] = m;
    mKinds[i] = kind;
    return i;
}

Index ParticleSet::addBatch(const std::vector<Vec3>& xs, Real m, ParticleKind kind)
{
    const Index first = Index(mPositions.size());
    growFor(xs.size());
    mPositions.insert(mPositions.end(), xs.begin(), xs.end());
    appendDefaults(xs.size());
    std::fill(mMasses.begin() + first, mMasses.end(), m);
    std::fill(mKinds.begin() + first, mKinds.end(), kind);
    return first;
}

std::size_t ParticleSet::removeIf(const std::vector<std::uint8_t>& remove)
{
    if (remove.size() != size()) {
        throw ValueError(msg("ParticleSet::removeIf: mask has ", remove.size(),
                             " entries, expected one per particle (", size(), ")"));
    }
    const std::size_t before = size();
    forEachChannel([&](auto& data) { compact(data, remove); });
    return before - size();
}

void ParticleSet::reorder(const std::vector<Index>& order)
{
    if (order.size() != size()) {
        throw ValueError(msg("ParticleSet::reorder: order has ", order.size(),
                             " entries, expected a permutation of ", size(), " particles"));
    }
    // A repeated index would duplicate a particle (and its id) and lose another: refuse it.
    std::vector<std::uint8_t> seen(order.size(), 0);
    for (std::size_t k = 0; k < order.size(); ++k) {
        if (order[k] >= order.size() || seen[order[k]]) {
            throw ValueError(msg("ParticleSet::reorder: entry ", k, " = ", order[k],
                                 " is out of range or repeated: expected a permutation of ", size(),
                                 " particles"));
        }
        seen[order[k]] = 1;
    }
    std::vector<Vec3> vecScratch;
    std::vector<Real> realScratch;
    std::vector<ParticleKind> kindScratch;
    std::vector<ParticleId> idScratch;
    permute(mPositions, order, vecScratch);
    permute(mVelocities, order, vecScratch);
    permute(mMasses, order, realScratch);
    permute(mDensities, order, realScratch);
    permute(mPressures, order, realScratch);
    permute(mKinds, order, kindScratch);
    permute(mIds, order, idScratch);
    for (auto& [name, ch] : mScalars) permute(ch.data, order, realScratch);
    for (auto& [name, ch] : mVectors) permute(ch.data, order, vecScratch);
}

void ParticleSet::append(const ParticleSet& other)
{
    const std::size_t n = size(), m = other.size();
    for (const auto& [name, ch] : other.mScalars) addScalarChannel(name, ch.defaultValue);
    for (const auto& [name, ch] : other.mVectors) addVectorChannel(name, ch.defaultValue);
    auto cat = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
    cat(mPositions, other.mPositions);
    cat(mVelocities, other.mVelocities);
    cat(mMasses, other.mMasses);
    cat(mDensities, other.mDensities);
    cat(mPressures, other.mPressures);
    cat(mKinds, other.mKinds);
    cat(mIds, other.mIds);
    for (auto& [name, ch] : mScalars) {
        auto it = other.mScalars.find(name);
        if (it != other.mScalars.end()) cat(ch.data, it->second.data);
        else ch.data.resize(n + m, ch.defaultValue);
    }
    for (auto& [name, ch] : mVectors) {
        auto it = other.mVectors.find(name);
        if (it != other.mVectors.end()) cat(ch.data, it->second.data);
        else ch.data.resize(n + m, ch.defaultValue);
    }
    // The larger counter, kept on this set's own sequence (setIdSequence).
    if (other.mNextId > mNextId)
        mNextId += (other.mNextId - mNextId + mIdStride - 1) / mIdStride * mIdStride;
}

ParticleSet ParticleSet::select(const std::vector<std::uint8_t>& keep) const
{
    if (keep.size() != size()) {
        throw ValueError(msg("ParticleSet::select: mask has ", keep.size(),
                             " entries, expected one per particle (", size(), ")"));
    }
    ParticleSet out = *this;
    std::vector<std::uint8_t> remove(keep.size());
    for (std::size_t i = 0; i < keep.size(); ++i) remove[i] = !keep[i];
    out.removeIf(remove);
    return out;
}

void ParticleSet::reserve(std::size_t n)
{
    forEachChannel([n](auto& data) { data.reserve(n); });
}

void ParticleSet::clear()
{
    forEachChannel([](auto& data) { data.clear(); });
}

std::size_t ParticleSet::count(ParticleKind kind) const
{
    return std::size_t(std::count(mKinds.begin(), mKinds.end(), kind));
}

void ParticleSet::setNextId(ParticleId next)
{
    const auto maxId = mIds.empty() ? ParticleId(-1) : *std::max_element(mIds.begin(), mIds.end());
    if (next <= maxId) {
        throw ValueError(msg("ParticleSet::setNextId(", next,
                             "): expected a value greater than "
                             "the largest id in the set (",
                             maxId, ")"));
    }
    mNextId = next;
}

void ParticleSet::setIdSequence(ParticleId next, ParticleId stride)
{
    if (stride < 1) {
        throw ValueError(msg("ParticleSet::setIdSequence: stride ", stride, ": expected >= 1"));
    }
    setNextId(next);
    mIdStride = stride;
}

std::vector<Real>& ParticleSet::addScalarChannel(const std::string& name, Real value)
{
    auto [it, inserted] = mScalars.try_emplace(name, ScalarChannel{{}, value});
    if (inserted) it->second.data.assign(size(), value);
    return it->second.data;
}

std::vector<Vec3>& ParticleSet::addVectorChannel(const std::string& name, const Vec3& value)
{
    auto [it, inserted] = mVectors.try_emplace(name, VectorChannel{{}, value});
    if (inserted) it->second.data.assign(size(), value);
    return it->second.data;
}

void ParticleSet::removeChannel(const std::string& name)
{
    mScalars.erase(name);
    mVectors.erase(name);
}

bool ParticleSet::hasScalarChannel(const std::string& name) const { return mScalars.count(name); }
bool ParticleSet::hasVectorChannel(const std::string& name) const { return mVectors.count(name); }

std::vector<Real>& ParticleSet::scalarChannel(const std::string& name)
{
    return const_cast<std::vector<Real>&>(std::as_const(*this).scalarChannel(name));
}

const std::vector<Real>& ParticleSet::scalarChannel(const std::string& name) const
{
    return findChannel(mScalars, name, "scalar").data;
}

std::vector<Vec3>& ParticleSet::vectorChannel(const std::string& name)
{
    return const_cast<std::vector<Vec3>&>(std::as_const(*this).vectorChannel(name));
}

const std::vector<Vec3>& ParticleSet::vectorChannel(const std::string& name) const
{
    return findChannel(mVectors, name, "vector").data;
}

Real ParticleSet::scalarChannelDefault(const std::string& name) const
{
    scalarChannel(name); // throws, naming the channels that exist, if it is missing
    return mScalars.find(name)->second.defaultValue;
}

void ParticleSet::setScalarChannelDefault(const std::string& name, Real value)
{
    scalarChannel(name);
    mScalars.find(name)->second.defaultValue = value;
}

Vec3 ParticleSet::vectorChannelDefault(const std::string& name) const
{
    vectorChannel(name);
    return mVectors.find(name)->second.defaultValue;
}

std::size_t ParticleSet::memoryBytes() const
{
    auto bytes = [](const auto& data) {
        return data.capacity() * sizeof(typename std::decay_t<decltype(data)>::value_type);
    };
    std::size_t total = bytes(mPositions) + bytes(mVelocities) + bytes(mMasses) + bytes(mDensities)
                        + bytes(mPressures) + bytes(mKinds) + bytes(mIds);
    for (const auto& [name, ch] : mScalars) total += bytes(ch.data);
    for (const auto& [name, ch] : mVectors) total += bytes(ch.data);
    return total;
}

std::vector<std::string> ParticleSet::scalarChannelNames() const { return keysOf(mScalars); }

std::vector<std::string> ParticleSet::vectorChannelNames() const { return keysOf(mVectors); }

} // namespace sph
} // namespace ghostfx
