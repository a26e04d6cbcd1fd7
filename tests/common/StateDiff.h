/// @file   StateDiff.h
/// @brief  Test helper: compare two solver states bit for bit (every built-in and named channel,
///         channel defaults, ids, next id, scalars), as resume and checkpoint tests need.
#pragma once

#include <ghostfx/sph/SolverState.h>

#include <cstring>
#include <string>
#include <vector>

namespace ghostfx {
namespace testing {

using sph::ParticleSet;
using sph::Real;
using sph::SolverState;
using sph::Vec3;

template <typename T>
inline bool sameBytes(const std::vector<T>& a, const std::vector<T>& b)
{
    return a.size() == b.size()
           && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// "" if two states are identical bit for bit (every channel, default, id, scalar), else what
/// differs first.
inline std::string firstDifference(const SolverState& a, const SolverState& b)
{
    const ParticleSet& p = a.particles;
    const ParticleSet& q = b.particles;
    if (a.solver != b.solver) return "solver";
    if (p.size() != q.size()) return "particle count";
    if (!sameBytes(p.positions(), q.positions())) return "positions";
    if (!sameBytes(p.velocities(), q.velocities())) return "velocities";
    if (!sameBytes(p.ids(), q.ids())) return "ids";
    if (!sameBytes(p.kinds(), q.kinds())) return "kinds";
    if (!sameBytes(p.masses(), q.masses())) return "masses";
    if (!sameBytes(p.densities(), q.densities())) return "densities";
    if (!sameBytes(p.pressures(), q.pressures())) return "pressures";
    if (p.nextId() != q.nextId()) return "next id";
    if (p.scalarChannelNames() != q.scalarChannelNames()) return "scalar channel names";
    if (p.vectorChannelNames() != q.vectorChannelNames()) return "vector channel names";
    for (const auto& name : p.scalarChannelNames()) {
        if (!sameBytes(p.scalarChannel(name), q.scalarChannel(name))) return "channel " + name;
        const Real da = p.scalarChannelDefault(name), db = q.scalarChannelDefault(name);
        if (std::memcmp(&da, &db, sizeof(Real)) != 0) return "default of " + name;
    }
    for (const auto& name : p.vectorChannelNames()) {
        if (!sameBytes(p.vectorChannel(name), q.vectorChannel(name))) return "channel " + name;
        const Vec3 da = p.vectorChannelDefault(name), db = q.vectorChannelDefault(name);
        if (std::memcmp(&da, &db, sizeof(Vec3)) != 0) return "default of " + name;
    }
    // Compare the doubles by their bits (NaN != NaN as values).
    if (a.reals.size() != b.reals.size()) return "reals";
    for (auto i = a.reals.begin(), j = b.reals.begin(); i != a.reals.end(); ++i, ++j) {
        if (i->first != j->first || std::memcmp(&i->second, &j->second, sizeof(double)) != 0) {
            return "real " + i->first;
        }
    }
    if (a.integers != b.integers) return "integers";
    return "";
}

} // namespace testing
} // namespace ghostfx
