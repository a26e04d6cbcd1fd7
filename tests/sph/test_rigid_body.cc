// A free rigid body's equations of motion against analytic answers: a throw under gravity,
// the torque-free precession of a symmetric top, impulses and the placement it reports.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/RigidBody.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace ghostfx;
using namespace ghostfx::sph;

namespace {

/// A body of mass m with the diagonal inertia (a, b, c) and its centre at `centre`.
MassProperties diagonalBody(double m, double a, double b, double c, const Vec3d& centre)
{
    MassProperties p;
    p.mass = m;
    p.volume = m / 1000;
    p.centre = centre;
    p.inertia = Mat3d(a, 0.0, 0.0, 0.0, b, 0.0, 0.0, 0.0, c);
    return p;
}

} // namespace

TEST(RigidBody, AThrowFollowsTheParabolaOfSemiImplicitEuler)
{
    // Semi-implicit Euler under a constant force: v_n = v0 + n dt g exactly, and
    // x_n = x0 + n dt v0 + dt^2 g n (n + 1) / 2 (the sum of the velocities it moved with).
    RigidBody body(diagonalBody(2, 1, 1, 1, Vec3d(0.1, 0.2, 0.3)));
    body.setVelocity(Vec3d(1, 2, 0));
    const Vec3d g(0, -9.81, 0);
    const double dt = 1e-3;
    const int n = 500;
    for (int k = 0; k < n; ++k) body.step(g * body.mass(), Vec3d(0.0), dt);
    const Vec3d x = Vec3d(0.1, 0.2, 0.3) + Vec3d(1, 2, 0) * (n * dt) + g * (dt * dt * n * (n + 1) / 2);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(body.state().position[a], x[a], 1e-12);
    EXPECT_NEAR(body.state().velocity[1], 2 - 9.81 * n * dt, 1e-12);
    EXPECT_NEAR(body.state().time, n * dt, 1e-12);
}

TEST(RigidBody, ATorqueFreeTopKeepsItsMomentumAndPrecessesAtLOverIPerpendicular)
{
    // A symmetric top (I1 = I2 = 1, I3 = 2.5) spinning about an axis off its symmetry axis.
    // Torque-free (Landau & Lifshitz, Mechanics Sec. 33): L is constant, the kinetic energy
    // L . omega / 2 is constant, and the symmetry axis turns about L at |L| / I1 keeping its
    // angle to L. Bounds: L exact to rounding (the integrator keeps L); energy and the cone
    // angle to 1e-6 over 2 turns at 1000 steps per turn (the orientation's midpoint update is
    // second order and symmetric; measured 3e-9 and 1e-8, where a first-order turn by the
    // start's omega drifted the cone by 3e-3); the precession's phase to 1e-2.
    RigidBody body(diagonalBody(1, 1, 1, 2.5, Vec3d(0.0)));
    body.setAngularVelocity(Vec3d(0.6, 0, 2.0));
    const Vec3d L = body.state().angularMomentum;
    const double energy = 0.5 * L.dot(body.angularVelocity());
    const Vec3d axis0 = body.rotation() * Vec3d(0, 0, 1);
    const double cone = std::acos(axis0.dot(L.unit()));
    const double rate = L.length() / 1.0, period = 2 * M_PI / rate;
    const int steps = 2000;
    const double dt = 2 * period / steps;
    for (int k = 0; k < steps / 4; ++k) body.step(Vec3d(0.0), Vec3d(0.0), dt);
    // A quarter of the run: half a turn of the axis about L.
    const Vec3d axis = body.rotation() * Vec3d(0, 0, 1);
    const Vec3d n = L.unit();
    auto across = [&](const Vec3d& a) { return (a - n * a.dot(n)).unit(); };
    const double turned = std::acos(std::max(-1.0, std::min(1.0, across(axis).dot(across(axis0)))));
    for (int k = steps / 4; k < steps; ++k) body.step(Vec3d(0.0), Vec3d(0.0), dt);
    const double energyAfter = 0.5 * body.state().angularMomentum.dot(body.angularVelocity());
    const double coneAfter = std::acos(body.rotation().col(2).dot(n));
    std::printf("[measured] top: energy %+.2e, cone %+.2e rad, half turn %.4f rad\n",
                energyAfter / energy - 1, coneAfter - cone, turned);
    for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(body.state().angularMomentum[a], L[a]);
    EXPECT_LT(std::abs(energyAfter / energy - 1), 1e-6);
    EXPECT_LT(std::abs(coneAfter - cone), 1e-6);
    EXPECT_NEAR(turned, M_PI, 1e-2 * M_PI);
}

TEST(RigidBody, AnImpulseAtAPointChangesBothMomentaAndTheEffectiveMassIsRight)
{
    // A unit impulse n at r from the centre: dv = n / m, dL = r x n. The velocity change of
    // the point along n is then n . (dv + I^-1 (r x n) x r), which is what inverseMassAlong
    // says (to rounding).
    RigidBody body(diagonalBody(4, 0.5, 0.8, 1.1, Vec3d(0.0)));
    const Vec3d x(0.2, -0.1, 0.05), n(0, 1, 0);
    const double before = body.pointVelocity(x).dot(n);
    const double k = body.inverseMassAlong(x, n);
    body.applyImpulse(x, n);
    EXPECT_NEAR(body.state().velocity[1], 0.25, 1e-15);
    EXPECT_NEAR(body.pointVelocity(x).dot(n) - before, k, 1e-14);
    EXPECT_GT(k, 0.25); // turning adds to the point's response
}

TEST(RigidBody, ThePlacementMovesTheLevelSetFrameAndGivesMaterialVelocities)
{
    // The body frame's point at the centre of mass goes to the state's position; a material
    // point's velocity from the placement's rates equals pointVelocity; a placement a time
    // ahead is the state moved on at its velocities.
    const Vec3d c(0.5, 0.2, -0.1);
    RigidBody body(diagonalBody(1, 0.1, 0.2, 0.3, c));
    RigidBodyState s = body.state();
    s.position = Vec3d(1, 2, 3);
    s.orientation = Quatd(Vec3d(0, 0, 1), 0.7);
    s.velocity = Vec3d(0.3, 0, -0.2);
    body.setState(s);
    body.setAngularVelocity(Vec3d(0, 0, 2));
    const RigidTransform now = body.placementAt(s.time);
    const Vec3 com = now.toWorld(Vec3(c));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(double(com[a]), s.position[a], 1e-5);
    const Vec3 local(0.7f, 0.1f, 0.0f);
    const Vec3 rate = now.translationRate + now.rotationRate * local;
    const Vec3d expected = body.pointVelocity(Vec3d(now.toWorld(local)));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(double(rate[a]), expected[a], 1e-5);
    const RigidTransform later = body.placementAt(s.time + 0.1);
    const Vec3 comLater = later.toWorld(Vec3(c));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(double(comLater[a]), s.position[a] + 0.1 * s.velocity[a], 1e-5);
}

TEST(RigidBody, AMasslessBodyIsRefused)
{
    EXPECT_THROW(RigidBody(diagonalBody(0, 1, 1, 1, Vec3d(0.0))), ValueError);
    EXPECT_THROW(RigidBody(diagonalBody(1, 0, 1, 1, Vec3d(0.0))), ValueError);
}
