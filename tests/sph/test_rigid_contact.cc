// Level-set contact of a rigid body (RigidContact.h) against rigid-body answers: a box rests
// on a floor without jitter, slides down a slope at g (sin a - mu cos a) or sticks when
// mu > tan a, and a drop bounces back to e^2 of its height.
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/MassProperties.h>
#include <ghostfx/sph/RigidContact.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace ghostfx;
using namespace ghostfx::sph;

namespace {

constexpr double G = 9.81, DT = 1e-3;

/// A 10 x 10 x 10 cm box of 500 kg/m^3 centred at `centre`, and points on its faces 1 cm apart.
struct Box
{
    LevelSet shape;
    std::vector<Vec3d> points;

    explicit Box(const Vec3& centre)
        : shape(makeLevelSet(makeBoxLevelSet(centre - Vec3(Real(0.05)), centre + Vec3(Real(0.05)),
                                             Real(0.005)),
                             "box"))
    {
        for (int i = 0; i <= 10; ++i) {
            for (int j = 0; j <= 10; ++j) {
                for (int k = 0; k <= 10; ++k) {
                    if (i % 10 && j % 10 && k % 10) continue;
                    points.push_back(Vec3d(centre) + Vec3d(i, j, k) * 0.01 - Vec3d(0.05));
                }
            }
        }
    }
};

/// A half-space solid below the plane through the origin with the unit normal n.
LevelSet slope(const Vec3d& n)
{
    auto sdf = [n](const openvdb::Vec3d& x) { return x.dot(n); };
    return makeLevelSet(
        levelSetFromSdf(sdf, Aabb{Vec3(-0.6f, -0.6f, -0.3f), Vec3(0.6f, 0.05f, 0.3f)}, Real(0.005)),
        "slope");
}

/// Steps of gravity, contact and drift; returns the body's velocity history's last value.
void run(RigidBody& body, const Box& box, const LevelSet& floor, const ContactSettings& cs,
         int steps, double* largestSpeedAfter = nullptr, int after = 0)
{
    ContactObstacle o;
    o.shape = &floor;
    for (int k = 0; k < steps; ++k) {
        body.accelerate(Vec3d(0, -G * body.mass(), 0), Vec3d(0.0), DT);
        resolveContact(body, box.points, o, DT, cs);
        body.drift(DT);
        if (largestSpeedAfter && k >= after)
            *largestSpeedAfter = std::max(*largestSpeedAfter, body.state().velocity.length());
    }
}

ContactSettings contact(double restitution, double friction)
{
    ContactSettings cs;
    cs.restitution = restitution;
    cs.friction = friction;
    cs.restSpeed = 3 * G * DT;
    cs.maxPushOut = 1e-3;
    return cs;
}

} // namespace

TEST(RigidContact, ABoxRestsOnAFloorWithoutJitter)
{
    // Dropped from 1 cm with no bounce: after 0.2 s its speed stays below 1e-3 m/s (gravity
    // gives g dt = 1e-2 m/s a step, which contact takes out each step) and it sinks less than
    // 0.5 mm into the floor (the level set's trilinear error at 5 mm voxels).
    const Box box(Vec3(0, Real(0.06), 0));
    RigidBody body(massProperties(box.shape, 500));
    const LevelSet floor = slope(Vec3d(0, 1, 0));
    double speed = 0;
    run(body, box, floor, contact(0, 0.5), 1000, &speed, 200);
    const double bottom = body.state().position[1] - 0.05;
    std::printf("[measured] resting box: bottom %.2e m, largest speed after 0.2 s %.2e m/s\n",
                bottom, speed);
    EXPECT_LT(speed, 1e-3);
    EXPECT_GT(bottom, -5e-4);
    EXPECT_LT(bottom, 1e-3);
}

TEST(RigidContact, ABoxSlidesDownASlopeAtCoulombsAccelerationOrSticks)
{
    // A slope of 30 degrees: with mu = 0.3 < tan 30 the box slides with a = g (sin 30 - mu
    // cos 30) = 2.36 m/s^2 (bound 5 %: the first-order contact takes one step to settle); with
    // mu = 0.8 > tan 30 it stays: no acceleration (below 1 % of g sin 30) and a speed below
    // 5 mm/s (what its first steps onto the slope leave; measured 1.1 mm/s).
    const double angle = M_PI / 6;
    const Vec3d n(-std::sin(angle), std::cos(angle), 0);
    const LevelSet floor = slope(n);
    for (const double mu : {0.3, 0.8}) {
        // The box turned onto the slope, its bottom face on it.
        const Box box(Vec3(0, Real(0.052), 0));
        RigidBody body(massProperties(box.shape, 500));
        RigidBodyState s = body.state();
        s.orientation = Quatd(Vec3d(0, 0, 1), angle);
        s.position = n * 0.0505;
        body.setState(s);
        run(body, box, floor, contact(0, mu), 100);
        const Vec3d v0 = body.state().velocity;
        run(body, box, floor, contact(0, mu), 300);
        const Vec3d v1 = body.state().velocity;
        const Vec3d down(-std::cos(angle), -std::sin(angle), 0);
        const double a = (v1 - v0).dot(down) / (300 * DT);
        const double expected = G * (std::sin(angle) - mu * std::cos(angle));
        std::printf("[measured] slope, mu %.1f: acceleration %.3f m/s^2 (Coulomb %.3f), speed %.2e\n",
                    mu, a, expected, v1.length());
        if (expected > 0) EXPECT_NEAR(a, expected, 0.05 * expected);
        else {
            EXPECT_LT(std::abs(a), 0.01 * G * std::sin(angle));
            EXPECT_LT(v1.length(), 5e-3);
        }
    }
}

TEST(RigidContact, ADropBouncesBackToRestitutionSquaredOfItsHeight)
{
    // Dropped from 20 cm with e = 0.5, no friction: it leaves the floor at e times its impact
    // speed and rises to e^2 h = 5 cm (bound 10 %: the impact is taken over one step of 1 ms at
    // 2 m/s, 2 mm of a 20 cm fall).
    const Box box(Vec3(0, Real(0.25), 0));
    RigidBody body(massProperties(box.shape, 500));
    const LevelSet floor = slope(Vec3d(0, 1, 0));
    ContactObstacle o;
    o.shape = &floor;
    const ContactSettings cs = contact(0.5, 0);
    bool bounced = false;
    double highest = 0;
    for (int k = 0; k < 800; ++k) {
        body.accelerate(Vec3d(0, -G * body.mass(), 0), Vec3d(0.0), DT);
        resolveContact(body, box.points, o, DT, cs);
        body.drift(DT);
        if (body.state().velocity[1] > 0) bounced = true;
        if (bounced) highest = std::max(highest, body.state().position[1] - 0.05);
    }
    std::printf("[measured] bounce: rose to %.4f m (e^2 h = 0.05 m)\n", highest);
    EXPECT_TRUE(bounced);
    EXPECT_NEAR(highest, 0.05, 0.005);
}

TEST(RigidContact, ABoxDroppedOnAnotherComesToRestOnIt)
{
    // Two 10 cm boxes, the upper dropped from 2 cm above the lower, which rests on the floor;
    // each pair of bodies is resolved both ways, then each body against the solids, and the
    // whole set swept eight times, as GhostSolver does (one sweep with the floor first left
    // the lower box the reaction of the upper's contact until the next step: g dt = 1 cm/s of
    // jitter). After 0.3 s the upper
    // rests on the lower: its bottom within 1 mm of the lower's top (the push-out's share of
    // an overlap a step), both slower than 1 mm/s, neither turned by more than a degree.
    const Box lowerBox(Vec3(0, Real(0.05), 0)), upperBox(Vec3(0, Real(0.17), 0));
    RigidBody lower(massProperties(lowerBox.shape, 500)), upper(massProperties(upperBox.shape, 500));
    const LevelSet floor = slope(Vec3d(0, 1, 0));
    const ContactSettings cs = contact(0.2, 0.5);
    for (int k = 0; k < 300; ++k) {
        for (RigidBody* b : {&lower, &upper})
            b->accelerate(Vec3d(0, -G * b->mass(), 0), Vec3d(0.0), DT);
        for (int pass = 0; pass < 8; ++pass) {
            ContactObstacle onLower, onUpper;
            onLower.shape = &lowerBox.shape;
            onLower.body = &lower;
            onUpper.shape = &upperBox.shape;
            onUpper.body = &upper;
            resolveContact(upper, upperBox.points, onLower, DT, cs);
            resolveContact(lower, lowerBox.points, onUpper, DT, cs);
            ContactObstacle ground;
            ground.shape = &floor;
            resolveContact(lower, lowerBox.points, ground, DT, cs);
            resolveContact(upper, upperBox.points, ground, DT, cs);
        }
        for (RigidBody* b : {&lower, &upper}) b->drift(DT);
    }
    const double gap = (upper.state().position[1] - 0.05) - (lower.state().position[1] + 0.05);
    const double turn = 2 * std::acos(std::min(1.0, std::abs(upper.state().orientation.w())));
    std::printf("[measured] stack: gap %.2e m, speeds %.2e %.2e m/s, upper turned %.2e rad\n", gap,
                upper.state().velocity.length(), lower.state().velocity.length(), turn);
    EXPECT_NEAR(gap, 0.0, 1e-3);
    EXPECT_LT(upper.state().velocity.length(), 1e-3);
    EXPECT_LT(lower.state().velocity.length(), 1e-3);
    EXPECT_LT(turn, M_PI / 180);
}
