/// @file   RigidMotion.h
/// @brief  Rigid placement of a solid, source or emitter as a function of time, shared by the
///         liquid and gas solvers.
#pragma once

#include <ghostfx/sph/LevelSet.h>
#include <ghostfx/sph/Types.h>

#include <openvdb/math/Mat3.h>

#include <functional>
#include <vector>

namespace ghostfx {
namespace sph {

/// Placement of a rigid body: world x = rotation * local + translation, local being the frame
/// its level set is defined in.
struct RigidTransform
{
    openvdb::math::Mat3<Real> rotation = openvdb::math::Mat3<Real>::identity();
    Vec3 translation{0};
    /// The rates of both at this time, where the motion knows them (hasRates): the velocity of
    /// the material point `local` is translationRate + rotationRate * local.
    openvdb::math::Mat3<Real> rotationRate = openvdb::math::Mat3<Real>::zero();
    Vec3 translationRate{0};
    bool hasRates = false;

    Vec3 toWorld(const Vec3& local) const { return rotation * local + translation; }
    Vec3 toLocal(const Vec3& world) const { return rotation.transpose() * (world - translation); }
    /// The world box around the placed corners of the local box `local` (empty stays empty).
    Aabb toWorld(const Aabb& local) const
    {
        Aabb box;
        if (local.empty()) return box;
        for (int c = 0; c < 8; ++c) {
            box.expand(toWorld(Vec3(c & 1 ? local.max[0] : local.min[0],
                                    c & 2 ? local.max[1] : local.min[1],
                                    c & 4 ? local.max[2] : local.min[2])));
        }
        return box;
    }
};

/// A body's placement as a function of time (s). It must be defined for every t >= 0. A motion
/// should set the rates of the transforms it returns; one that does not must be smooth enough
/// for a central difference of 1e-4 s to give its velocity (in single precision that loses
/// digits as positions grow: about 0.5 % of the speed 10 m from the origin).
using RigidMotion = std::function<RigidTransform(double time)>;

/// Translation at a constant velocity (m/s) from the origin at t = 0.
inline RigidMotion constantVelocity(const Vec3& velocity)
{
    return [velocity](double time) {
        RigidTransform xf;
        xf.translation = Vec3(Vec3d(velocity) * time);
        xf.translationRate = velocity;
        xf.hasRates = true;
        return xf;
    };
}

/// A rigid body given by a level set in its local frame and its motion: what both solvers keep
/// per solid.
struct MovingLevelSet
{
    LevelSet shape;
    RigidMotion motion;

    RigidTransform at(double time) const { return motion(time); }
    /// Level-set value at a world point x at `time`.
    Real phi(const Vec3& x, double time) const { return shape.phi(at(time).toLocal(x)); }
    /// Velocity (m/s) of the body's material point `local` at `time`: from the motion's rates,
    /// or, for a motion without them, a central difference of 1e-4 s (one-sided at t = 0).
    Vec3 velocity(const Vec3& local, double time) const
    {
        const RigidTransform xf = at(time);
        if (xf.hasRates) return xf.translationRate + xf.rotationRate * local;
        constexpr double DELTA = 1e-4;
        const double t0 = time > DELTA ? time - DELTA : 0.0, t1 = time + DELTA;
        return (at(t1).toWorld(local) - at(t0).toWorld(local)) / Real(t1 - t0);
    }
};

/// Where each of `solids` (pointers to MovingLevelSet or derived) is at `time` (s).
template <typename Solids>
std::vector<RigidTransform> placementsAt(const Solids& solids, double time)
{
    std::vector<RigidTransform> placements;
    placements.reserve(solids.size());
    for (const auto& solid : solids) placements.push_back(solid->at(time));
    return placements;
}

/// What collideWithSolid did with one particle.
enum class Collision {
    None,      ///< outside the solid: untouched
    Projected, ///< moved to the surface, velocity into the solid removed
    Restored,  ///< deeper than the level set's band: back where it started the step
    Stuck      ///< deeper than the band, and so was its start: left where it is
};

/// [SB12] Sec. 3 "Solid Collisions" for one particle x (velocity v) and one solid placed by xf
/// at `time`: a particle inside goes to the surface (closest point, or steps along the smooth
/// normal where that oscillates at edges and corners) and loses its velocity into the solid.
/// Beyond the band the level set is clamped and gives no direction: the particle goes back to
/// `previous` (its position at the start of the step) if that is outside the solid now, moving
/// with the solid; otherwise it is Stuck, and the caller must stop with an error (a particle
/// inside a wall is a wrong answer, not a slow one).
inline Collision collideWithSolid(const MovingLevelSet& solid, const RigidTransform& xf,
                                  double time, const Vec3& previous, Vec3& x, Vec3& v)
{
    const Vec3 local = xf.toLocal(x);
    if (!(solid.shape.phi(local) < Real(0))) return Collision::None;
    SurfaceProjection proj = solid.shape.projectToSurface(local);
    if (!proj.converged) proj = solid.shape.pushOutside(local);
    if (proj.converged) {
        const Vec3 nrm = xf.rotation * solid.shape.normal(proj.point);
        x = xf.toWorld(proj.point);
        const Real vn = (v - solid.velocity(proj.point, time)).dot(nrm);
        if (vn < Real(0)) v -= vn * nrm;
        return Collision::Projected;
    }
    const Vec3 before = xf.toLocal(previous);
    if (!(solid.shape.phi(before) < Real(0))) {
        x = previous;
        v = solid.velocity(before, time);
        return Collision::Restored;
    }
    return Collision::Stuck;
}

} // namespace sph
} // namespace ghostfx
