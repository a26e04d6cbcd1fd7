/// @file   RigidContact.cc
/// @brief  Level-set contact impulses of a rigid body (RigidContact.h).
#include "ghostfx/sph/RigidContact.h"

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace sph {

namespace {

/// The obstacle's placement at the step's end and the velocity of its material point at x.
struct PlacedObstacle
{
    const ContactObstacle& o;
    RigidTransform place;

    PlacedObstacle(const ContactObstacle& obstacle, double dt)
        : o(obstacle)
    {
        if (o.body) place = o.body->placementAt(o.body->state().time + dt);
        else if (o.moving) place = o.moving->at(o.time);
    }
    /// phi (m) at the world point x and the outward unit normal there (zero beyond the band).
    Real phi(const Vec3d& x, Vec3d* normal) const
    {
        const Vec3 local = place.toLocal(Vec3(x));
        const Real value = o.shape->phi(local);
        if (normal) *normal = Vec3d(place.rotation * o.shape->normal(local));
        return value;
    }
    Vec3d velocity(const Vec3d& x) const
    {
        if (o.body) return o.body->pointVelocity(x);
        if (o.moving) return Vec3d(o.moving->velocity(place.toLocal(Vec3(x)), o.time));
        return Vec3d(0.0);
    }
    double inverseMassAlong(const Vec3d& x, const Vec3d& n) const
    {
        return o.body ? o.body->inverseMassAlong(x, n) : 0.0;
    }
};

/// The normal velocity a contact point should leave with (RigidContact.h): to the surface
/// from outside, out at the capped rate from inside, bouncing above the rest speed.
double targetNormalSpeed(double phiNow, double vn, double dt, const ContactSettings& s)
{
    double target = phiNow >= 0 ? -phiNow / dt : std::min(-phiNow, s.maxPushOut) / dt;
    if (vn < -s.restSpeed) target = std::max(target, -s.restitution * vn);
    return target;
}

/// The impulse at contact point x (normal n) that brings its relative normal velocity to the
/// target, with friction opposing the tangential one.
Vec3d contactImpulse(const RigidBody& body, const PlacedObstacle& other, const Vec3d& x,
                     const Vec3d& n, const Vec3d& relative, double target, double friction)
{
    const double vn = relative.dot(n);
    const double jn = (target - vn) / (body.inverseMassAlong(x, n) + other.inverseMassAlong(x, n));
    Vec3d J = n * jn;
    const Vec3d vt = relative - n * vn;
    const double speed = vt.length();
    if (speed > 0 && friction > 0) {
        const Vec3d t = vt / speed;
        const double kt = body.inverseMassAlong(x, t) + other.inverseMassAlong(x, t);
        J -= t * std::min(friction * jn, speed / kt);
    }
    return J;
}

} // namespace

int resolveContact(RigidBody& body, const std::vector<Vec3d>& points,
                   const ContactObstacle& obstacle, double dt, const ContactSettings& settings)
{
    int touching = 0;
    for (int sweep = 0; sweep < settings.sweeps; ++sweep) {
        const PlacedObstacle other(obstacle, dt);
        const Mat3d R = body.rotation();
        const Vec3d com = body.state().position, centre = body.localCentre();
        touching = 0;
        for (const Vec3d& p : points) {
            const Vec3d x = R * (p - centre) + com;
            const Vec3d v = body.pointVelocity(x);
            Vec3d n;
            if (!(other.phi(x + v * dt, &n) < 0) || n.lengthSqr() < 0.25) continue;
            ++touching;
            const Vec3d relative = v - other.velocity(x);
            const double vn = relative.dot(n);
            const double target = targetNormalSpeed(double(other.phi(x, nullptr)), vn, dt, settings);
            if (!(target > vn)) continue;
            const Vec3d J = contactImpulse(body, other, x, n, relative, target, settings.friction);
            body.applyImpulse(x, J);
            if (obstacle.body) obstacle.body->applyImpulse(x, -J);
        }
    }
    return touching;
}

} // namespace sph
} // namespace ghostfx
