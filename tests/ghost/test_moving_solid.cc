/// @file   test_moving_solid.cc
/// @brief  Moving solids ([SB12] Sec. 4.4): ghosts follow the rigid motion and carry its
///         velocity; liquid is pushed, never left inside.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {
constexpr Real H = Real(0.01);
}

TEST(MovingSolid, PaddlePushesLiquidAndLeavesNoneInside)
{
    // A 2 x 8 x 8 cm paddle starts left of a drop at rest (no gravity) and moves right at
    // 0.5 m/s, rotating about y at 2 rad/s.
    GhostSettings s;
    s.spacing = H;
    s.gravity = Vec3(0);
    GhostSolver solver(s);
    const LevelSet paddle = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.01f, -0.04f, -0.04f), Vec3(0.01f, 0.04f, 0.04f), H / 2), "paddle");
    const double omega = 2.0, speed = 0.5;
    auto motion = [=](double t) {
        RigidTransform xf;
        xf.rotation = openvdb::math::rotation<openvdb::math::Mat3<Real>>(openvdb::math::Y_AXIS,
                                                                         Real(omega * t));
        xf.translation = Vec3(Real(-0.08 + speed * t), 0, 0);
        return xf;
    };
    solver.addMovingSolid(paddle, motion);
    solver.addLiquid(
        makeLevelSet(makeSphereLevelSet(Vec3(0.02f, 0, 0), Real(0.05), H / 2), "drop"));

    const Real dt = Real(1) / 1200;
    for (int k = 0; k < 120; ++k) solver.step(dt); // 0.1 s: the paddle advances 5 cm
    const ParticleSet p = solver.allParticles();
    const RigidTransform now = motion(solver.time());
    double worstGhost = 0, worstVelocity = 0, deepest = 0, momentumX = 0;
    const auto& local = p.vectorChannel("solid_x");
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3& x = p.positions()[i];
        if (p.kinds()[i] == ParticleKind::GhostSolid) {
            // Ghosts sit at their material point and move with the paddle. Analytic velocity of
            // R(omega t) l + c(t): omega dR/dtheta l + c', and for a rotation about y,
            // dR/dtheta l = R(theta + pi/2) l - (0, l_y, 0) whatever the sign convention.
            worstGhost = std::max(worstGhost, double((x - now.toWorld(local[i])).length()));
            const auto quarter = openvdb::math::rotation<openvdb::math::Mat3<Real>>(
                openvdb::math::Y_AXIS, Real(omega * solver.time() + M_PI / 2));
            const Vec3 dRl = quarter * local[i] - Vec3(0, local[i][1], 0);
            const Vec3 expected = Real(omega) * dRl + Vec3(Real(speed), 0, 0);
            worstVelocity = std::max(worstVelocity,
                                     double((p.vectorChannel("solid_v")[i] - expected).length()));
        } else if (p.kinds()[i] == ParticleKind::Liquid) {
            deepest = std::min(deepest, double(paddle.phi(now.toLocal(x))));
            momentumX += double(p.masses()[i]) * p.velocities()[i][0];
        }
    }
    std::printf("[measured] moving solid: ghost placement error %.2e m, velocity error %.2e m/s, "
                "deepest liquid %.2e m, liquid x-momentum %.4f kg m/s\n",
                worstGhost, worstVelocity, deepest, momentumX);
    EXPECT_LT(worstGhost, 1e-5);           // float round-off of the transform (positions ~0.1 m)
    EXPECT_LT(worstVelocity, 1e-3);        // central difference of 1e-4 s on a 2 rad/s rotation
    EXPECT_GE(deepest, -0.01 * double(H)); // collision projection tolerance
    EXPECT_GT(momentumX, 0.0);             // the paddle pushed the liquid to the right
}

TEST(MovingSolid, PerFrameShapeReplacesTheGhosts)
{
    // A deforming solid given as one level set per frame: a floor that rises 1 cm. Its ghosts
    // are resampled from the new shape; no liquid is left inside it.
    GhostSettings s;
    s.spacing = H;
    GhostSolver solver(s);
    auto floorAt = [](Real top) {
        return makeLevelSet(
            makeBoxLevelSet(Vec3(-0.08f, -0.1f, -0.08f), Vec3(0.08f, top, 0.08f), H / 2), "floor");
    };
    solver.addSolid(floorAt(Real(-0.05)));
    solver.addLiquid(makeLevelSet(
        makeBoxLevelSet(Vec3(-0.05f, -0.05f, -0.05f), Vec3(0.05f, 0.0f, 0.05f), H / 2), "pool"));
    solver.advanceFrame();
    const std::size_t liquid = solver.count(ParticleKind::Liquid);
    const LevelSet raised = floorAt(Real(-0.04));
    solver.setSolidShape(0, raised);
    solver.advanceFrame();
    double deepest = 0, highestGhost = -1;
    const ParticleSet all = solver.allParticles();
    for (std::size_t i = 0; i < all.size(); ++i) {
        const Vec3& x = all.positions()[i];
        if (all.kinds()[i] == ParticleKind::Liquid) {
            deepest = std::min(deepest, double(raised.phi(x)));
        } else if (all.kinds()[i] == ParticleKind::GhostSolid) {
            highestGhost = std::max(highestGhost, double(x[1]));
        }
    }
    EXPECT_EQ(solver.count(ParticleKind::Liquid), liquid);
    EXPECT_GE(deepest, -0.01 * double(H));
    // The new ghosts reach the new top (-0.04 m) within the trilinear/projection tolerance.
    EXPECT_NEAR(highestGhost, -0.04, 0.1 * double(H));
    EXPECT_THROW(solver.setSolidShape(3, raised), ValueError);
}
