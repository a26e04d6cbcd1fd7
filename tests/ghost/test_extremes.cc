/// @file   test_extremes.cc
/// @brief  Stability at the extremes: stiffness over three orders of magnitude, XSPH epsilon
///         0 to 1, time steps up to and past the CFL limit, for both methods. Every run either
///         stays finite and below the speed bound or stops with the blow-up error; none
///         produces NaN silently. Inside the CFL limit, none may blow up.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.01);

struct Outcome
{
    bool blewUp = false;
    std::string message;
    double maxSpeed = 0;
};

/// A floor slab 3 h thick under the drop (built once: sampling it is most of a short run).
const LevelSet& floorLevelSet()
{
    static const LevelSet floor = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.05f, -0.08f, -0.05f), Vec3(0.05f, -0.05f, 0.05f), H / 2), "floor");
    return floor;
}

/// A drop falling onto a floor, `steps` steps of dt = cfl * h / c (c the sound speed).
Outcome runDrop(Method method, Real stiffness, Real epsilon, Real cfl, int steps)
{
    GhostSettings s;
    s.method = method;
    s.spacing = H;
    s.stiffness = stiffness;
    s.xsphEpsilon = epsilon;
    s.seed = 1;
    GhostSolver solver(s);
    solver.addSolid(floorLevelSet());
    solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.02), H / 2), "drop"),
                     Vec3(0, -1, 0));
    const Real dt = cfl * H / s.soundSpeed();
    Outcome out;
    try {
        for (int k = 0; k < steps; ++k) solver.step(dt);
    } catch (const NumericalError& e) {
        out.blewUp = true;
        out.message = e.what();
        return out;
    }
    for (std::size_t i = 0; i < solver.particles().size(); ++i) {
        const Vec3& x = solver.particles().positions()[i];
        const Vec3& v = solver.particles().velocities()[i];
        EXPECT_TRUE(isFinite(x) && isFinite(v)) << "silent NaN, particle " << i;
        out.maxSpeed = std::max(out.maxSpeed, double(v.length()));
    }
    EXPECT_LE(out.maxSpeed, double(s.speedLimit()));
    return out;
}

} // namespace

TEST(Extremes, StiffnessEpsilonAndTimeStepSweepNeverGivesSilentNaN)
{
    int blowUps = 0, runs = 0, basicInsideCfl = 0;
    for (const Method method : {Method::Ghost, Method::Basic}) {
        for (const Real k : {Real(200), Real(2000), Real(200000)}) {
            for (const Real eps : {Real(0), Real(0.05), Real(1)}) {
                for (const Real cfl : {Real(0.4), Real(1.5), Real(6)}) {
                    const Outcome o = runDrop(method, k, eps, cfl, 30);
                    ++runs;
                    if (o.blewUp) {
                        ++blowUps;
                        basicInsideCfl += method == Method::Basic && cfl <= Real(0.4);
                        // The error names where and why.
                        EXPECT_NE(o.message.find("blew up at frame 0, step "), std::string::npos);
                        EXPECT_NE(o.message.find("reduce the time step"), std::string::npos);
                    }
                    // Inside the acoustic CFL limit every Ghost SPH combination must run. Basic
                    // SPH's Lennard-Jones walls are stiffer than the liquid (their force grows as
                    // r^-13) and need a smaller step than the acoustic limit when the drop hits
                    // the floor, whatever k: with fixed steps some Basic runs stop with the error
                    // (the CFL-adaptive stepper also limits dt by the largest acceleration).
                    if (method == Method::Ghost && cfl <= Real(0.4)) {
                        EXPECT_FALSE(o.blewUp) << methodName(method) << " k " << k << " eps " << eps
                                               << " cfl " << cfl << ": " << o.message;
                    }
                }
            }
        }
    }
    std::printf("[measured] extremes: %d runs, %d stopped with the blow-up error (%d of them "
                "Basic SPH inside the acoustic CFL limit), the rest stayed finite\n",
                runs, blowUps, basicInsideCfl);
    // Far past the limit (cfl 6) the stiff runs do blow up: the detector must have fired.
    EXPECT_GT(blowUps, 0);
}

TEST(Extremes, CflAdaptiveSteppingRunsAStiffLiquid)
{
    // k = 2e5 Pa: sound speed 37 m/s; fixed 20 substeps at 30 fps (dt = 1/600 s) would be CFL
    // 6. The adaptive stepper picks dt <= 0.4 h / (c + |v|) and runs.
    GhostSettings s;
    s.spacing = H;
    s.stiffness = Real(200000);
    s.substeps = 0;
    s.cflNumber = Real(0.4);
    GhostSolver solver(s);
    solver.addSolid(makeLevelSet(
        makeBoxLevelSet(Vec3(-0.08f, -0.1f, -0.08f), Vec3(0.08f, -0.05f, 0.08f), H / 2), "floor"));
    solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.025), H / 2), "drop"));
    solver.advanceFrame();
    EXPECT_NEAR(solver.time(), 1.0 / 30.0, 1e-12);
    // dt ~ 0.4 * 0.01 / 37 = 1.1e-4 s: about 300 steps for the frame.
    EXPECT_GT(solver.stepCount(), 250u);
    EXPECT_LT(solver.stepCount(), 400u);
}

namespace {

/// What a dam break looks like at one time: the surge front (99th percentile of x), the
/// column left at the back wall (99th percentile of y over x < 5 cm) and the largest speed
/// over the run so far.
struct Collapse
{
    double front = 0, column = 0, maxSpeed = 0;
    std::uint64_t steps = 0;
    GhostSolver::InitialDensityError initial;
};

double percentile(std::vector<double> values, double q)
{
    if (values.empty()) return 0;
    const std::size_t k = std::min(values.size() - 1, std::size_t(q * double(values.size())));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
    return values[k];
}

/// The column of issue 18: 0.1 x 0.2 x 0.1 m of water at 10 mm in a closed 0.6 x 0.3 x 0.1 m
/// tank (walls one kernel radius thick), CFL steps, 0.25 s (30 frames at 120 fps).
Collapse runCollapse(Real stiffness, Real cfl, Real epsilon)
{
    GhostSettings s;
    s.spacing = H;
    s.stiffness = stiffness;
    s.cflNumber = cfl;
    s.xsphEpsilon = epsilon;
    s.solidEpsilon = epsilon;
    s.substeps = 0;
    s.frameRate = Real(120);
    s.seed = 1;
    GhostSolver solver(s);
    const openvdb::Vec3d lo(0, 0, 0), hi(0.6, 0.3, 0.1), w(s.supportRadius());
    static const LevelSet tank = makeLevelSet(levelSetFromSdf(
                                                  [lo, hi, w](const openvdb::Vec3d& x) {
        return std::max(-boxSignedDistance(x, lo, hi), boxSignedDistance(x, lo - w, hi + w));
                                                  },
                                                  Aabb{Vec3(lo - w), Vec3(hi + w)}, H / 2),
                                              "tank");
    solver.addSolid(tank);
    solver.addLiquid(
        makeLevelSet(makeBoxLevelSet(Vec3(0, 0, 0), Vec3(0.1f, 0.2f, 0.1f), H / 2), "column"));
    Collapse out;
    for (int frame = 0; frame < 30; ++frame) {
        solver.advanceFrame();
        const ParticleSet& p = solver.particles();
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            out.maxSpeed = std::max(out.maxSpeed, double(p.velocities()[i].length()));
        }
    }
    const ParticleSet& p = solver.particles();
    std::vector<double> x, back;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        x.push_back(p.positions()[i].x());
        if (p.positions()[i].x() < 0.05) back.push_back(p.positions()[i].y());
    }
    out.front = percentile(x, 0.99);
    out.column = percentile(back, 0.99);
    out.steps = solver.stepCount();
    out.initial = solver.initialDensityError();
    return out;
}

} // namespace

TEST(Extremes, StiffCollapseAgreesWithTheReferenceStiffness)
{
    // Issue 18: a stiffer liquid must collapse like a softer one, not merely stay finite.
    const Collapse ref = runCollapse(Real(20000), Real(0.4), Real(0.05));
    std::printf("[measured] collapse k 2e4 cfl 0.4 eps 0.05: front %.3f m, column %.3f m, "
                "max speed %.2f m/s, %llu steps\n",
                ref.front, ref.column, ref.maxSpeed, (unsigned long long)ref.steps);
    const double freeFall = std::sqrt(2 * 9.81 * 0.2);
    struct Case
    {
        Real k, cfl, eps;
    };
    for (const Case c :
         {Case{2000, 0.4f, 0.05f}, Case{200000, 0.4f, 0.05f}, Case{20000, 0.2f, 0.05f},
          Case{20000, 0.4f, 0.02f}, Case{20000, 0.4f, 0.1f}}) {
        const Collapse o = runCollapse(c.k, c.cfl, c.eps);
        std::printf("[measured] collapse k %g cfl %g eps %g: front %.3f m (%+.1f %%), column "
                    "%.3f m (%+.1f %%), max speed %.2f m/s (%.1f x free fall), %llu steps\n",
                    double(c.k), double(c.cfl), double(c.eps), o.front,
                    100 * (o.front / ref.front - 1), o.column, 100 * (o.column / ref.column - 1),
                    o.maxSpeed, o.maxSpeed / freeFall, (unsigned long long)o.steps);
        // Measured (float, 2026-11-23): k 2e3 +6.6 % / -11.2 %, k 2e5 -12.3 % / +11.1 % (the
        // liquid's XSPH acts once per step, and k = 2e5 takes 3x the steps: more damping),
        // CFL 0.2 -0.5 % / -0.5 %, epsilon 0.02 and 0.1 +8.7 % and -10.2 % / -6.1 % and
        // +4.6 %; largest speed 0.9-2.3 x free fall. Before this round k = 2e5 reached 9-62 m/s
        // (4.7-31 x) and its front lagged 16-28 %. Over 12 sample realisations (the sampler's
        // seed salted, both volume relaxations; bench/history/diary-2026-11.md, "Tests that hold
        // over sample realisations") k 2e5 measured front -9.5 to -16.4 % and column +14.8 to
        // +38.4 % (one outlier; the rest to +22.7 %; the double build -19.0 % / +21.0 %). Bounds:
        // front 25 %, column 45 %; speed 4 x sqrt(2 g H), which a blow-up passes.
        EXPECT_NEAR(o.front / ref.front, 1.0, 0.25) << "k " << c.k << " eps " << c.eps;
        EXPECT_NEAR(o.column / ref.column, 1.0, 0.45) << "k " << c.k << " eps " << c.eps;
        EXPECT_LT(o.maxSpeed, 4 * freeFall) << "k " << c.k << " eps " << c.eps;
        if (c.k > Real(20000)) {
            // Above k = 2e4 the sampled liquid is relaxed before the first step. Measured:
            // sampled 3.25 % mean, 13.7 % largest |rho / rho0 - 1|, relaxed 0.64 % and 3.96 %
            // (float); the double build's samples, 2.92 % / 13.3 %, relax to 0.99 % / 7.74 %.
            // Over 12 sample realisations: Algorithm 2's samples 2.72-3.29 % mean relax to
            // 0.51-1.09 % (0.16-0.37 of it), largest 3.96-9.42 %; packing's 1.79-2.14 % relax to
            // 0.57-1.03 % (0.27-0.49 of it), largest 7.06-12.55 %. Bounds: the sampled liquid
            // has an error to relax (above 1 %), relaxed below 1.5 % mean and 15 % largest, and
            // at most 0.6 of the sampled mean.
            std::printf("[measured] initial density error k %g: sampled mean %.2f %% max %.2f "
                        "%%, relaxed mean %.2f %% max %.2f %%\n",
                        double(c.k), 100 * o.initial.meanSampled, 100 * o.initial.maxSampled,
                        100 * o.initial.meanRelaxed, 100 * o.initial.maxRelaxed);
            EXPECT_GT(o.initial.meanSampled, 0.01);
            EXPECT_LT(o.initial.meanRelaxed, 0.015);
            EXPECT_LT(o.initial.meanRelaxed, 0.6 * o.initial.meanSampled);
            EXPECT_LT(o.initial.maxRelaxed, 0.15);
        }
    }
    EXPECT_LT(ref.maxSpeed, 4 * freeFall);
}
