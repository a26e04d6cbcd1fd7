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
/// from outside, no nearer from inside, bouncing above the rest speed.
double targetNormalSpeed(double phiNow, double vn, double dt, double restitution,
                         const ContactSettings& s)
{
    double target = phiNow >= 0 ? -phiNow / dt : 0.0;
    if (vn < -s.restSpeed) target = std::max(target, -restitution * vn);
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

/// The body's surface points in the world, where its state places them.
std::vector<Vec3d> placedPoints(const RigidBody& body, const std::vector<Vec3d>& points)
{
    const Mat3d R = body.rotation();
    const Vec3d com = body.state().position, centre = body.localCentre();
    std::vector<Vec3d> world;
    world.reserve(points.size());
    for (const Vec3d& p : points) world.push_back(R * (p - centre) + com);
    return world;
}

/// A contact of the body's points with the obstacle: the points that end the coming drift
/// inside it, their mean (x) and mean normal (n).
struct Manifold
{
    int points = 0;
    Vec3d x{0.0}, n{0.0};
};

Manifold findManifold(const RigidBody& body, const std::vector<Vec3d>& world,
                      const PlacedObstacle& other, double dt)
{
    Manifold m;
    for (const Vec3d& x : world) {
        Vec3d n;
        if (!(other.phi(x + body.pointVelocity(x) * dt, &n) < 0) || n.lengthSqr() < 0.25) continue;
        ++m.points;
        m.x += x;
        m.n += n;
    }
    if (m.points == 0 || m.n.lengthSqr() == 0) return Manifold();
    m.x /= double(m.points);
    m.n = m.n.unit();
    return m;
}

/// Push the body out of the obstacle along the deepest point's normal, by at most maxPushOut:
/// a correction of position, so an overlap separates without the body gaining speed.
void pushOut(RigidBody& body, const std::vector<Vec3d>& points, const PlacedObstacle& other,
             double maxPushOut)
{
    double deepest = 0;
    Vec3d normal(0.0);
    for (const Vec3d& x : placedPoints(body, points)) {
        Vec3d n;
        const double phi = double(other.phi(x, &n));
        if (phi < deepest && n.lengthSqr() >= 0.25) {
            deepest = phi;
            normal = n;
        }
    }
    if (deepest == 0) return;
    RigidBodyState s = body.state();
    s.position += normal * std::min(-deepest, maxPushOut);
    body.setState(s);
}

} // namespace

int resolveContact(RigidBody& body, const std::vector<Vec3d>& points,
                   const ContactObstacle& obstacle, double dt, const ContactSettings& settings)
{
    // First the contact as a whole: one impulse at the mean of the touching points with their
    // mean normal, with the restitution (a face landing flat bounces without spinning); then
    // the points one by one without restitution, for what the whole left (a tilt, a corner).
    const std::vector<Vec3d> world = placedPoints(body, points);
    const Manifold m = findManifold(body, world, PlacedObstacle(obstacle, dt), dt);
    if (m.points == 0) return 0;
    {
        const PlacedObstacle other(obstacle, dt);
        const Vec3d relative = body.pointVelocity(m.x) - other.velocity(m.x);
        const double vn = relative.dot(m.n);
        const double target =
            targetNormalSpeed(double(other.phi(m.x, nullptr)), vn, dt, settings.restitution, settings);
        if (target > vn) {
            const Vec3d J = contactImpulse(body, other, m.x, m.n, relative, target, settings.friction);
            body.applyImpulse(m.x, J);
            if (obstacle.body) obstacle.body->applyImpulse(m.x, -J);
        }
    }
    for (int sweep = 0; sweep < settings.sweeps; ++sweep) {
        const PlacedObstacle other(obstacle, dt);
        for (const Vec3d& x : placedPoints(body, points)) {
            const Vec3d v = body.pointVelocity(x);
            Vec3d n;
            if (!(other.phi(x + v * dt, &n) < 0) || n.lengthSqr() < 0.25) continue;
            const Vec3d relative = v - other.velocity(x);
            const double vn = relative.dot(n);
            const double target = targetNormalSpeed(double(other.phi(x, nullptr)), vn, dt, 0.0, settings);
            if (!(target > vn)) continue;
            const Vec3d J = contactImpulse(body, other, x, n, relative, target, settings.friction);
            body.applyImpulse(x, J);
            if (obstacle.body) obstacle.body->applyImpulse(x, -J);
        }
    }
    pushOut(body, points, PlacedObstacle(obstacle, dt), settings.maxPushOut);
    return m.points;
}

} // namespace sph
} // namespace ghostfx
