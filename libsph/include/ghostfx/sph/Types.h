/// @file   Types.h
/// @brief  Scalar and vector types shared by every ghostfx library, and small math helpers.
/// @details `Real` is float by default and double when ghostfx is configured with
///          GHOSTFX_DOUBLE=ON; both builds must pass the tests. Particle vectors use OpenVDB's
///          math::Vec3 so level-set queries and point I/O need no conversions (DESIGN.md).
#pragma once

#include <openvdb/math/Vec3.h>

#include <cmath>
#include <cstdint>
#include <limits>

namespace ghostfx {
namespace sph {

#ifdef GHOSTFX_DOUBLE
using Real = double;
#else
using Real = float;
#endif

/// 3-vector of Real: positions (m), velocities (m/s), accelerations (m/s^2), gradients.
using Vec3 = openvdb::math::Vec3<Real>;
/// Double-precision 3-vector, for sums that must not lose precision (centres of mass, momenta).
using Vec3d = openvdb::math::Vec3<double>;

/// Index of a particle in a particle set (position in the arrays, changes when the set is sorted).
using Index = std::uint32_t;
/// Stable particle identifier: never reused within a particle set, survives sorting and removal.
using ParticleId = std::int64_t;

/// Marker for "no particle" returned by searches that found nothing.
constexpr Index INVALID_INDEX = std::numeric_limits<Index>::max();

constexpr Real PI = Real(3.14159265358979323846);

/// x^2
template <typename T>
constexpr T sqr(T x)
{
    return x * x;
}
/// x^3
template <typename T>
constexpr T cube(T x)
{
    return x * x * x;
}
/// Clamp x into [lo, hi].
template <typename T>
constexpr T clamp(T x, T lo, T hi)
{
    return x < lo ? lo : (hi < x ? hi : x);
}

/// True when every component is a finite number (no NaN, no infinity).
template <typename T>
inline bool isFinite(const openvdb::math::Vec3<T>& v)
{
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// Convert any OpenVDB 3-vector to a Vec3 of Real.
template <typename T>
inline Vec3 toVec3(const openvdb::math::Vec3<T>& v)
{
    return Vec3(Real(v[0]), Real(v[1]), Real(v[2]));
}

/// Axis-aligned box in world space (m).
struct Aabb
{
    Vec3 min{std::numeric_limits<Real>::max()};
    Vec3 max{-std::numeric_limits<Real>::max()};

    bool empty() const { return min[0] > max[0] || min[1] > max[1] || min[2] > max[2]; }
    void expand(const Vec3& x)
    {
        min = openvdb::math::minComponent(min, x);
        max = openvdb::math::maxComponent(max, x);
    }
    void expand(const Aabb& b)
    {
        if (!b.empty()) {
            expand(b.min);
            expand(b.max);
        }
    }
    bool contains(const Vec3& x) const
    {
        return x[0] >= min[0] && x[1] >= min[1] && x[2] >= min[2] && x[0] <= max[0]
               && x[1] <= max[1] && x[2] <= max[2];
    }
    Vec3 extent() const { return empty() ? Vec3(0) : max - min; }
    Vec3 center() const { return Real(0.5) * (min + max); }
    /// The box grown by `margin` (m) on every side.
    Aabb padded(Real margin) const
    {
        Aabb b = *this;
        if (!b.empty()) {
            b.min -= Vec3(margin);
            b.max += Vec3(margin);
        }
        return b;
    }
    /// The boxes share a point (an empty box meets none).
    bool intersects(const Aabb& o) const
    {
        return !empty() && !o.empty() && min[0] <= o.max[0] && o.min[0] <= max[0]
               && min[1] <= o.max[1] && o.min[1] <= max[1] && min[2] <= o.max[2]
               && o.min[2] <= max[2];
    }
};

} // namespace sph
} // namespace ghostfx
