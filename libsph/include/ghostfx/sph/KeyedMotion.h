/// @file   KeyedMotion.h
/// @brief  Rigid motion through keys, as an animator sets them: translation and three angles
///         at given times, interpolated linearly between them.
/// @details Scenes give a moving solid or source its keys (`"motion": { "keys": [...] }`,
///          docs/scene-format.md); the solvers see the result as a RigidMotion with exact rates
///          (RigidMotion.h).
#pragma once

#include <ghostfx/sph/RigidMotion.h>
#include <ghostfx/sph/Types.h>

#include <openvdb/math/Mat3.h>

#include <vector>

namespace ghostfx {
namespace sph {

/// One key of a rigid motion: at `time` (s) the body's local frame is rotated by
/// `rotateDegrees` (about x, then y, then z) and moved by `translate` (m).
struct RigidKey
{
    double time = 0;
    Vec3d translate{0};
    Vec3d rotateDegrees{0};
};

/// Piecewise-linear rigid motion through keys: translation and the three angles are
/// interpolated linearly (exact for a rotation about one axis); held constant before the first
/// and after the last key.
struct KeyedMotion
{
    std::vector<RigidKey> keys; ///< in increasing time

    /// The interpolated key at time t (s).
    RigidKey at(double time) const;
    /// Its time derivative: translate in m/s, rotateDegrees in degrees/s (zero outside the keys;
    /// at a key, the rate of the segment that starts there).
    RigidKey rate(double time) const;
    /// The motion as the solvers take it, its rates from the keys themselves (not a difference
    /// of placements).
    RigidMotion motion() const;

    /// Rotation for column vectors, world = R * local + translate: R = Rz * Ry * Rx.
    static openvdb::math::Mat3d rotation(const Vec3d& degrees);
    /// dR/dt of rotation(degrees) while the angles change at degreesPerSecond.
    static openvdb::math::Mat3d rotationRate(const Vec3d& degrees, const Vec3d& degreesPerSecond);
};

} // namespace sph
} // namespace ghostfx
