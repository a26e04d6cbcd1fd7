/// @file   RigidBody.h
/// @brief  A free rigid body: its mass properties, its state (centre of mass, orientation as a
///         unit quaternion, linear velocity, angular momentum) and one step of its equations of
///         motion under a force and a torque.
/// @details The body's own frame is the frame its level set is given in; the state places it:
///          world x = R(q) (local - c) + x_com, with c the centre of mass in that frame. The
///          state is in double precision, whatever Real is.
///
///          A step (semi-implicit Euler) takes the linear and angular momentum by the force and
///          the torque, turns the orientation by the new angular momentum's angular velocity,
///          omega = I_world^-1 L with I_world = R I R^T, taken at the half-turned orientation
///          (the midpoint rule), and then moves the centre of mass.
///          Keeping L rather than omega makes a torque-free body keep its angular momentum
///          exactly, and its precession follows from the inertia turning with the body: a
///          symmetric top spinning off its axis precesses at L / I_perp (the test in
///          tests/sph/test_rigid_body.cc).
#pragma once

#include <ghostfx/sph/MassProperties.h>
#include <ghostfx/sph/RigidMotion.h>

#include <openvdb/math/Mat3.h>
#include <openvdb/math/Quat.h>
#include <openvdb/math/Vec3.h>

namespace ghostfx {
namespace sph {

using Mat3d = openvdb::math::Mat3d;
using Quatd = openvdb::math::Quatd;

/// R(q) for a unit quaternion, acting on column vectors (R * v), element (i, j) = R_ij.
Mat3d rotationOf(const Quatd& q);

/// What a body is made of and how it touches others.
struct RigidBodyMaterial
{
    double restitution = 0.2; ///< of the normal velocity at an impact, in [0, 1]
    double friction = 0.5;    ///< Coulomb coefficient of the tangential impulse, >= 0
};

/// A body's state: what decides how it moves on (and what a checkpoint keeps).
struct RigidBodyState
{
    Vec3d position{0.0};              ///< centre of mass (m, world)
    Quatd orientation{0, 0, 0, 1};    ///< unit quaternion turning the body frame into the world
    Vec3d velocity{0.0};              ///< of the centre of mass (m/s)
    Vec3d angularMomentum{0.0};       ///< about the centre of mass (kg m^2 / s, world)
    double time = 0;                  ///< s
};

class RigidBody
{
public:
    /// A body of the given mass properties (in its level set's frame) at rest where its level
    /// set is, from time 0.
    /// @throw ValueError for a mass that is not > 0 or an inertia that is not invertible.
    explicit RigidBody(const MassProperties& mass, const RigidBodyMaterial& material = {});

    const MassProperties& massProperties() const { return mMass; }
    const RigidBodyMaterial& material() const { return mMaterial; }
    double mass() const { return mMass.mass; }
    /// The centre of mass in the body's frame (m).
    const Vec3d& localCentre() const { return mMass.centre; }

    const RigidBodyState& state() const { return mState; }
    /// Replace the state (a restored checkpoint, a script placing the body): taken as it is,
    /// except an orientation more than 1e-12 from unit length, which is normalised.
    void setState(const RigidBodyState& state);
    void setVelocity(const Vec3d& v) { mState.velocity = v; }
    /// Relabel the state's time (s), as a solver's clock snaps to a frame's end.
    void setTime(double time) { mState.time = time; }
    /// Set the angular velocity (rad/s, world): L = I_world omega.
    void setAngularVelocity(const Vec3d& omega);

    /// The rotation R(q) from the body frame to the world.
    Mat3d rotation() const;
    /// The inertia tensor about the centre of mass in world axes, R I R^T (kg m^2).
    Mat3d worldInertia() const;
    /// omega = I_world^-1 L (rad/s).
    Vec3d angularVelocity() const;
    /// Velocity (m/s) of the material point at the world point x: v + omega x (x - x_com).
    Vec3d pointVelocity(const Vec3d& x) const;
    /// The inverse effective mass of the body at the world point x along the unit n, for an
    /// impulse there: 1/m + n . (I_world^-1 (r x n)) x r, r = x - x_com.
    double inverseMassAlong(const Vec3d& x, const Vec3d& n) const;
    /// Give the impulse J (N s) at the world point x: momentum and angular momentum change.
    void applyImpulse(const Vec3d& x, const Vec3d& J);

    /// The placement of the body's frame at `time` (s): the state moved on at its velocities
    /// from the state's time (exact at that time; solvers ask between steps, and for the end
    /// of a step before the body has stepped), with the rates set.
    RigidTransform placementAt(double time) const;

    /// Change the momenta by a force and torque (N, N m, world, torque about the centre of
    /// mass) over dt (s): the first half of step().
    void accelerate(const Vec3d& force, const Vec3d& torque, double dt);
    /// Move and turn by the velocities over dt (s) and advance the state's time: the second
    /// half of step().
    void drift(double dt);
    /// One step: accelerate(), then drift().
    void step(const Vec3d& force, const Vec3d& torque, double dt)
    {
        accelerate(force, torque, dt);
        drift(dt);
    }

private:
    /// I_world^-1 L with the body turned to `orientation`.
    Vec3d angularVelocityAt(const Quatd& orientation) const;

    MassProperties mMass;
    Mat3d mInverseInertia; ///< in the body's axes
    RigidBodyMaterial mMaterial;
    RigidBodyState mState;
};

} // namespace sph
} // namespace ghostfx
