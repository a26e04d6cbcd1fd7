/// @file   RigidBody.cc
/// @brief  A free rigid body's equations of motion (RigidBody.h).
#include "ghostfx/sph/RigidBody.h"

#include "ghostfx/sph/Exceptions.h"

#include <cmath>

namespace ghostfx {
namespace sph {

Mat3d rotationOf(const Quatd& q)
{
    const double x = q.x(), y = q.y(), z = q.z(), w = q.w();
    return Mat3d(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y));
}

namespace {

/// The quaternion of a turn by the rotation vector `angle` (rad; its direction the axis).
Quatd turnBy(const Vec3d& angle)
{
    const double theta = angle.length();
    if (theta < 1e-300) return Quatd(0, 0, 0, 1);
    return Quatd(angle / theta, theta);
}

/// The cross-product matrix [w]x: [w]x v = w x v.
Mat3d crossMatrix(const Vec3d& w)
{
    return Mat3d(0.0, -w[2], w[1], w[2], 0.0, -w[0], -w[1], w[0], 0.0);
}

} // namespace

RigidBody::RigidBody(const MassProperties& mass, const RigidBodyMaterial& material)
    : mMass(mass)
    , mMaterial(material)
{
    if (!(mass.mass > 0) || !std::isfinite(mass.mass)) {
        throw ValueError(msg("rigid body: mass ", mass.mass, " kg: expected a finite value > 0"));
    }
    const double det = mass.inertia.det();
    if (!(det > 0) || !std::isfinite(det)) {
        throw ValueError("rigid body: its inertia tensor is not positive definite (a shape "
                         "with no volume?)");
    }
    mInverseInertia = mass.inertia.inverse();
    mState.position = mass.centre;
}

void RigidBody::setState(const RigidBodyState& state)
{
    // A saved state is taken bit for bit (normalising a unit quaternion again can change its
    // last bits, and a resumed run would part from the original).
    mState = state;
    const double norm = mState.orientation.dot(mState.orientation);
    if (std::abs(norm - 1) > 1e-12) mState.orientation = mState.orientation.unit();
}

void RigidBody::setAngularVelocity(const Vec3d& omega)
{
    mState.angularMomentum = worldInertia() * omega;
}

Mat3d RigidBody::rotation() const { return rotationOf(mState.orientation); }

Mat3d RigidBody::worldInertia() const
{
    const Mat3d R = rotation();
    return R * mMass.inertia * R.transpose();
}

Vec3d RigidBody::angularVelocity() const { return angularVelocityAt(mState.orientation); }

Vec3d RigidBody::angularVelocityAt(const Quatd& orientation) const
{
    const Mat3d R = rotationOf(orientation);
    return R * (mInverseInertia * (R.transpose() * mState.angularMomentum));
}

Vec3d RigidBody::pointVelocity(const Vec3d& x) const
{
    return mState.velocity + angularVelocity().cross(x - mState.position);
}

double RigidBody::inverseMassAlong(const Vec3d& x, const Vec3d& n) const
{
    const Mat3d R = rotation();
    const Vec3d r = x - mState.position;
    const Vec3d turn = R * (mInverseInertia * (R.transpose() * r.cross(n)));
    return 1.0 / mMass.mass + n.dot(turn.cross(r));
}

void RigidBody::applyImpulse(const Vec3d& x, const Vec3d& J)
{
    mState.velocity += J / mMass.mass;
    mState.angularMomentum += (x - mState.position).cross(J);
}

RigidTransform RigidBody::placementAt(double time) const
{
    const double dt = time - mState.time;
    const Vec3d omega = angularVelocity();
    const Quatd q = dt == 0 ? mState.orientation : (turnBy(omega * dt) * mState.orientation).unit();
    const Vec3d com = mState.position + mState.velocity * dt;
    const Mat3d R = rotationOf(q);
    RigidTransform xf;
    // world = R (local - c) + com = R local + (com - R c); its rate: omega x R local + ...
    const Vec3d translation = com - R * mMass.centre;
    const Mat3d rate = crossMatrix(omega) * R;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            xf.rotation(i, j) = Real(R(i, j));
            xf.rotationRate(i, j) = Real(rate(i, j));
        }
    }
    xf.translation = Vec3(translation);
    xf.translationRate = Vec3(mState.velocity - rate * mMass.centre);
    xf.hasRates = true;
    return xf;
}

void RigidBody::accelerate(const Vec3d& force, const Vec3d& torque, double dt)
{
    mState.velocity += force * (dt / mMass.mass);
    mState.angularMomentum += torque * dt;
}

void RigidBody::drift(double dt)
{
    // The turn by the angular velocity at the half-turned orientation (the midpoint rule:
    // second order, where the turn by the start's omega drifts the top's cone by 3e-3 rad
    // over two turns at 1000 steps a turn).
    const Quatd& q = mState.orientation;
    const Quatd half = (turnBy(angularVelocity() * (dt / 2)) * q).unit();
    mState.orientation = (turnBy(angularVelocityAt(half) * dt) * q).unit();
    mState.position += mState.velocity * dt;
    mState.time += dt;
}

} // namespace sph
} // namespace ghostfx
