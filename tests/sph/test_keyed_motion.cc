/// @file   test_keyed_motion.cc
/// @brief  Keyed rigid motion (sph::KeyedMotion): interpolation between keys, their rates
///         against finite differences, and the motion the solvers follow.
#include <ghostfx/sph/KeyedMotion.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace ghostfx;

TEST(KeyedMotion, InterpolatesAndHolds)
{
    sph::KeyedMotion m;
    m.keys = {{0.0, sph::Vec3d(0), sph::Vec3d(0)},
              {1.0, sph::Vec3d(2, 0, 0), sph::Vec3d(0, 90, 0)}};
    EXPECT_EQ(m.at(-1).translate, sph::Vec3d(0));
    EXPECT_EQ(m.at(0.5).translate, sph::Vec3d(1, 0, 0));
    EXPECT_DOUBLE_EQ(m.at(0.5).rotateDegrees[1], 45.0);
    EXPECT_EQ(m.at(3).translate, sph::Vec3d(2, 0, 0));
    // 90 degrees about y takes +x to -z (right-handed), to round-off.
    const openvdb::math::Mat3d r = sph::KeyedMotion::rotation(sph::Vec3d(0, 90, 0));
    const sph::Vec3d x = r * sph::Vec3d(1, 0, 0);
    EXPECT_NEAR(x[0], 0, 1e-12);
    EXPECT_NEAR(x[2], -1, 1e-12);
}

TEST(KeyedMotion, RatesAreTheDerivativesOfTheKeys)
{
    sph::KeyedMotion m;
    m.keys = {{0.0, sph::Vec3d(0), sph::Vec3d(0)},
              {2.0, sph::Vec3d(4, 0, -2), sph::Vec3d(30, 90, -60)}};
    const sph::RigidKey rate = m.rate(0.7);
    EXPECT_EQ(rate.translate, sph::Vec3d(2, 0, -1));
    EXPECT_EQ(rate.rotateDegrees, sph::Vec3d(15, 45, -30));
    EXPECT_EQ(m.rate(-1).translate, sph::Vec3d(0));      // held before the first key
    EXPECT_EQ(m.rate(2.5).rotateDegrees, sph::Vec3d(0)); // and after the last
    // dR/dt against a central difference of the rotation in double precision (step 1e-6 s:
    // truncation error ~1e-12 relative; the analytic form must agree to 1e-8).
    const double t = 0.7, dt = 1e-6;
    const openvdb::math::Mat3d analytic =
        sph::KeyedMotion::rotationRate(m.at(t).rotateDegrees, rate.rotateDegrees);
    const openvdb::math::Mat3d numeric =
        (sph::KeyedMotion::rotation(m.at(t + dt).rotateDegrees)
         - sph::KeyedMotion::rotation(m.at(t - dt).rotateDegrees))
        * (0.5 / dt);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            EXPECT_NEAR(analytic(i, j), numeric(i, j), 1e-8) << i << "," << j;
    }
}

TEST(KeyedMotion, TheSolversMotionHasTheKeysPlacementsAndRates)
{
    // motion() is what a moving solid or source follows: its transform at t is the keys'
    // rotation and translation, and a material point's velocity the keys' own rates.
    sph::KeyedMotion m;
    m.keys = {{0.0, sph::Vec3d(0), sph::Vec3d(0)},
              {2.0, sph::Vec3d(4, 0, -2), sph::Vec3d(0, 90, 0)}};
    const sph::RigidMotion motion = m.motion();
    const sph::RigidTransform xf = motion(1.0);
    EXPECT_TRUE(xf.hasRates);
    const sph::Vec3 moved = xf.toWorld(sph::Vec3(1, 0, 0));
    // 45 degrees about y takes +x to (cos 45, 0, -sin 45), then the translation (2, 0, -1).
    EXPECT_NEAR(moved[0], 2 + std::sqrt(0.5), 1e-6);
    EXPECT_NEAR(moved[2], -1 - std::sqrt(0.5), 1e-6);
    // Velocity of that point: translation rate (2, 0, -1) plus dR/dt x, 45 deg/s about y.
    const sph::Vec3 v = xf.translationRate + xf.rotationRate * sph::Vec3(1, 0, 0);
    const double w = 45 * M_PI / 180;
    EXPECT_NEAR(v[0], 2 - w * std::sqrt(0.5), 1e-5);
    EXPECT_NEAR(v[2], -1 - w * std::sqrt(0.5), 1e-5);
}
