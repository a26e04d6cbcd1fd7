/// @file   RigidMotion.h
/// @brief  Rigid placement of a solid, source or emitter as a function of time, shared by the
///         liquid and gas solvers.
#pragma once

#include <ghostfx/sph/Types.h>

#include <openvdb/math/Mat3.h>

#include <functional>

namespace ghostfx {
namespace sph {

/// Placement of a rigid body: world x = rotation * local + translation, local being the frame
/// its level set is defined in.
struct RigidTransform
{
    openvdb::math::Mat3<Real> rotation = openvdb::math::Mat3<Real>::identity();
    Vec3 translation{0};

    Vec3 toWorld(const Vec3& local) const { return rotation * local + translation; }
    Vec3 toLocal(const Vec3& world) const { return rotation.transpose() * (world - translation); }
};

/// A body's placement as a function of time (s). It must be defined for every t >= 0 and be
/// smooth enough for a central difference of 1e-4 s to give its velocity.
using RigidMotion = std::function<RigidTransform(double time)>;

} // namespace sph
} // namespace ghostfx
