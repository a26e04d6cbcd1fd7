/// @file   Random.h
/// @brief  Small, fast, portable random number generator for sampling and seeding.
/// @details PCG32 (O'Neill 2014, "PCG: a family of simple fast space-efficient statistically
///          good algorithms for random number generation"), XSH-RR output. Unlike the standard
///          library's distributions, every draw here is defined by this file alone, so a seed
///          gives the same particles with any compiler or standard library: sampling is
///          reproducible and checkpoints can store the generator state.
#pragma once

#include "ghostfx/sph/Types.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace ghostfx {
namespace sph {

class Rng
{
public:
    /// @param seed    selects the sequence start
    /// @param stream  selects one of 2^63 independent sequences (e.g. a sweep or a cell index)
    explicit Rng(std::uint64_t seed = 0, std::uint64_t stream = 0)
    {
        mInc = (stream << 1u) | 1u;
        mState = 0;
        next();
        mState += seed + 0x853c49e6748fea9bULL;
        next();
    }

    /// Uniform 32-bit integer.
    std::uint32_t next()
    {
        const std::uint64_t old = mState;
        mState = old * MULTIPLIER + mInc;
        return output(old);
    }

    /// Uniform integer in [0, n), n > 0 (Lemire's multiply-shift; bias below 2^-32 n).
    std::uint32_t below(std::uint32_t n)
    {
        return std::uint32_t((std::uint64_t(next()) * std::uint64_t(n)) >> 32u);
    }

    /// Uniform double in [0, 1), 32 random bits.
    double uniform01() { return double(next()) * (1.0 / 4294967296.0); }
    /// Uniform Real in [lo, hi).
    Real uniform(Real lo, Real hi) { return lo + (hi - lo) * Real(uniform01()); }

    /// Uniform direction on the unit sphere: a point drawn uniformly in the cube [-1, 1]^3,
    /// kept if it falls inside the unit ball (52% of draws) and normalised. Cheaper than the
    /// trigonometric methods, and exact.
    Vec3 unitVector()
    {
        for (;;) {
            const double x = 2.0 * uniform01() - 1.0, y = 2.0 * uniform01() - 1.0,
                         z = 2.0 * uniform01() - 1.0;
            const double len2 = x * x + y * y + z * z;
            if (len2 <= 1.0 && len2 > 1e-6) {
                const double inv = 1.0 / std::sqrt(len2);
                return Vec3(Real(x * inv), Real(y * inv), Real(z * inv));
            }
        }
    }

    /// `count` directions, the same as `count` calls of unitVector() (and the generator left
    /// in the same state), but drawn several at a time: the 32-bit draws come from four
    /// interleaved copies of the sequence, each jumping four steps ahead, so the multiplies
    /// overlap instead of waiting on each other.
    void unitVectors(Vec3* out, int count)
    {
        constexpr int TRIES = 16, CHUNK = 3 * TRIES; // a multiple of 4 (copies)
        std::uint32_t draws[CHUNK];
        std::uint64_t states[CHUNK];
        double x[TRIES], y[TRIES], z[TRIES], inv[TRIES];
        bool accept[TRIES];
        int made = 0;
        while (made < count) {
            fill(draws, states, CHUNK);
            // Every try of the chunk at once, without a branch (half the tries are rejected,
            // at random, so a branch is mispredicted about every other try).
            for (int j = 0; j < TRIES; ++j) {
                x[j] = 2.0 * toUnit(draws[3 * j]) - 1.0;
                y[j] = 2.0 * toUnit(draws[3 * j + 1]) - 1.0;
                z[j] = 2.0 * toUnit(draws[3 * j + 2]) - 1.0;
                const double len2 = x[j] * x[j] + y[j] * y[j] + z[j] * z[j];
                accept[j] = (len2 <= 1.0) & (len2 > 1e-6);
                inv[j] = 1.0 / std::sqrt(std::max(len2, 1e-6)); // exact where accepted
            }
            // Kept tries in order; a rejected one is written to the next free slot (made <
            // count) and overwritten by the next kept one.
            int j = 0;
            for (; j < TRIES && made < count; ++j) {
                out[made] = Vec3(Real(x[j] * inv[j]), Real(y[j] * inv[j]), Real(z[j] * inv[j]));
                made += int(accept[j]);
            }
            if (j < TRIES) mState = states[3 * j]; // the state before the first unused draw
        }
    }

    /// Uniform point in the unit ball.
    Vec3 inUnitBall() { return unitVector() * Real(std::cbrt(uniform01())); }

    /// Generator state, for checkpoints.
    std::uint64_t state() const { return mState; }
    std::uint64_t increment() const { return mInc; }
    void restore(std::uint64_t state, std::uint64_t increment)
    {
        mState = state;
        mInc = increment;
    }

private:
    static constexpr std::uint64_t MULTIPLIER = 6364136223846793005ULL;

    /// XSH-RR: the 32-bit output of the state before a step.
    static std::uint32_t output(std::uint64_t old)
    {
        const std::uint32_t xorShifted = std::uint32_t(((old >> 18u) ^ old) >> 27u);
        const std::uint32_t rot = std::uint32_t(old >> 59u);
        return (xorShifted >> rot) | (xorShifted << ((32u - rot) & 31u));
    }

    static double toUnit(std::uint32_t draw) { return double(draw) * (1.0 / 4294967296.0); }

    /// The next n draws (n a multiple of 4) and the state before each; advances the state by n.
    void fill(std::uint32_t* draws, std::uint64_t* states, int n)
    {
        // Four steps of s -> M s + inc are s -> M^4 s + inc (M^3 + M^2 + M + 1), mod 2^64.
        const std::uint64_t m2 = MULTIPLIER * MULTIPLIER, m4 = m2 * m2;
        const std::uint64_t c4 = mInc * ((MULTIPLIER + 1) * (m2 + 1));
        std::uint64_t s[4];
        s[0] = mState;
        for (int j = 1; j < 4; ++j) s[j] = s[j - 1] * MULTIPLIER + mInc;
        for (int k = 0; k < n; k += 4) {
            for (int j = 0; j < 4; ++j) {
                states[k + j] = s[j];
                draws[k + j] = output(s[j]);
                s[j] = s[j] * m4 + c4;
            }
        }
        mState = s[0];
    }

    std::uint64_t mState = 0;
    std::uint64_t mInc = 1;
};

} // namespace sph
} // namespace ghostfx
