/// @file   ParticleSet.h
/// @brief  Structure-of-arrays particle storage with built-in and named solver channels.
/// @details One set may hold several kinds of particle (liquid, ghost air, ghost solid, gas,
///          boundary) distinguished by the `kind` channel. Every particle carries a stable id,
///          never reused within the set, so exporters and tests can follow a particle while the
///          set is sorted by neighbour-grid cell or compacted after removals. Solvers add their
///          own per-particle quantities as named channels (scalar or vector); exporters read them
///          by name without knowing the solver (DESIGN.md, "Particles").
#pragma once

#include "ghostfx/sph/Types.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace ghostfx {
namespace sph {

/// What a particle represents. Values are stored in files: append, never renumber.
enum class ParticleKind : std::uint8_t {
    Liquid = 0,     ///< liquid particle ([SB12])
    GhostAir = 1,   ///< ghost particle in the air layer around the liquid ([SB12] Sec. 4.3)
    GhostSolid = 2, ///< ghost particle inside a solid ([SB12] Sec. 4.4)
    Gas = 3,        ///< gas particle ([RYY15])
    Boundary = 4,   ///< static boundary particle (Basic SPH solids, [RYY15] rigid boundaries)
};

/// Lower-case name of a kind ("liquid", "ghost_air", ...), as used in files and logs.
const char* kindName(ParticleKind kind);

class ParticleSet
{
public:
    ParticleSet() = default;

    std::size_t size() const { return mPositions.size(); }
    bool empty() const { return mPositions.empty(); }

    /// Append one particle and give it the next id. Named channels get their default value.
    /// @param x  position (m)   @param v  velocity (m/s)   @param m  mass (kg)
    /// @return its index
    Index add(const Vec3& x, const Vec3& v, Real m, ParticleKind kind);

    /// Append `count` particles of one kind at positions `xs` (velocity zero, mass `m`).
    /// @return index of the first new particle
    Index addBatch(const std::vector<Vec3>& xs, Real m, ParticleKind kind);

    /// Remove every particle i with `remove[i] != 0`, keeping the others in their order.
    /// @return number removed
    std::size_t removeIf(const std::vector<std::uint8_t>& remove);

    /// Reorder all channels so that new particle k is old particle `order[k]`.
    /// `order` must be a permutation of [0, size()).
    void reorder(const std::vector<Index>& order);

    void reserve(std::size_t n);
    void clear();

    /// Append every particle of `other`, ids included (the caller keeps ids unique). Channels
    /// of either set that the other lacks are filled with their default value. The id counter
    /// becomes the larger of the two.
    void append(const ParticleSet& other);
    /// The particles i with `keep[i] != 0`, in order, with every channel and the id counter.
    ParticleSet select(const std::vector<std::uint8_t>& keep) const;

    /// Number of particles of one kind.
    std::size_t count(ParticleKind kind) const;

    /// The id the next added particle will get.
    ParticleId nextId() const { return mNextId; }
    /// Restore the id counter (checkpoint resume). Must exceed every id in the set.
    void setNextId(ParticleId next);
    /// Hand out ids next, next + stride, next + 2 stride, ...: processes that share one
    /// simulation each take their own residue modulo the process count, so the ids they give
    /// new particles never collide. `next` must exceed every id in the set; stride >= 1.
    void setIdSequence(ParticleId next, ParticleId stride);
    ParticleId idStride() const { return mIdStride; }

    // Built-in channels ----------------------------------------------------------------------
    std::vector<Vec3>& positions() { return mPositions; } ///< x (m)
    const std::vector<Vec3>& positions() const { return mPositions; }
    std::vector<Vec3>& velocities() { return mVelocities; } ///< v (m/s)
    const std::vector<Vec3>& velocities() const { return mVelocities; }
    std::vector<Real>& masses() { return mMasses; } ///< m (kg)
    const std::vector<Real>& masses() const { return mMasses; }
    std::vector<Real>& densities() { return mDensities; } ///< rho (kg/m^3)
    const std::vector<Real>& densities() const { return mDensities; }
    std::vector<Real>& pressures() { return mPressures; } ///< p (Pa)
    const std::vector<Real>& pressures() const { return mPressures; }
    std::vector<ParticleKind>& kinds() { return mKinds; }
    const std::vector<ParticleKind>& kinds() const { return mKinds; }
    std::vector<ParticleId>& ids() { return mIds; }
    const std::vector<ParticleId>& ids() const { return mIds; }

    // Named solver channels ------------------------------------------------------------------
    /// Add (or fetch, if it exists) a scalar channel filled with `value`.
    std::vector<Real>& addScalarChannel(const std::string& name, Real value = Real(0));
    /// Add (or fetch, if it exists) a vector channel filled with `value`.
    std::vector<Vec3>& addVectorChannel(const std::string& name, const Vec3& value = Vec3(0));

    /// Drop a named channel (scalar or vector); nothing happens if it does not exist.
    void removeChannel(const std::string& name);

    bool hasScalarChannel(const std::string& name) const;
    bool hasVectorChannel(const std::string& name) const;
    /// Throw ValueError naming the channel and the channels that exist, if it is missing.
    std::vector<Real>& scalarChannel(const std::string& name);
    const std::vector<Real>& scalarChannel(const std::string& name) const;
    std::vector<Vec3>& vectorChannel(const std::string& name);
    const std::vector<Vec3>& vectorChannel(const std::string& name) const;

    /// Names of the solver channels, sorted.
    std::vector<std::string> scalarChannelNames() const;
    std::vector<std::string> vectorChannelNames() const;

    /// The value a channel gives to particles added after it was created (the `value` passed
    /// to addScalarChannel / addVectorChannel). Throws ValueError like scalarChannel() if the
    /// channel is missing. Checkpoints store it so a resumed set fills new particles alike.
    Real scalarChannelDefault(const std::string& name) const;
    Vec3 vectorChannelDefault(const std::string& name) const;
    /// Change the value particles added from now on get in a scalar channel (those already in
    /// the set keep theirs). Throws ValueError like scalarChannel() if the channel is missing.
    void setScalarChannelDefault(const std::string& name, Real value);

    /// Bytes held by the arrays of every channel, built-in and named: the sum of each vector's
    /// capacity() times its element size. Capacity, not size, because that is what the process
    /// holds (vectors grow geometrically, so this can exceed size-based bytes by up to 2x after
    /// growth); container bookkeeping (vector headers, map nodes, channel names) is left out.
    /// Divide by size() for bytes per particle.
    std::size_t memoryBytes() const;

private:
    template <typename Fn>
    void forEachChannel(Fn&& fn);
    void growFor(std::size_t count);
    void appendDefaults(std::size_t count);

    struct ScalarChannel
    {
        std::vector<Real> data;
        Real defaultValue;
    };
    struct VectorChannel
    {
        std::vector<Vec3> data;
        Vec3 defaultValue;
    };

    std::vector<Vec3> mPositions, mVelocities;
    std::vector<Real> mMasses, mDensities, mPressures;
    std::vector<ParticleKind> mKinds;
    std::vector<ParticleId> mIds;
    std::map<std::string, ScalarChannel> mScalars;
    std::map<std::string, VectorChannel> mVectors;
    ParticleId mNextId = 0;
    ParticleId mIdStride = 1;
};

} // namespace sph
} // namespace ghostfx
