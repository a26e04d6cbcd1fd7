/// @file   bench_bodies.cc
/// @brief  The cost of a dynamic solid: a still tank with a floating box, the box dynamic
///         (GhostSolver::addDynamicSolid) against the same box on a keyed motion (a bob of 1 cm
///         at 1 Hz), time per step with either pressure model.
/// @details The tank is 60 x 60 cm inside, the water 25 cm deep, the box 20 x 10 x 20 cm of
///          500 kg/m^3 floating at its draft; `--spacing` sets h (0.015 m: about 25,000 liquid
///          particles). Each run takes `--warmup` steps and then times `--steps` steps at the
///          fixed dt = 0.2 h / c (Tait) or the CFL step (DFSPH). The two variants run
///          interleaved, `--pairs` times, so the VM's drift falls on both (RESULTS.md,
///          "Dynamic solids"); the median per step of each is printed, and the ratio.
///
///          Run: build/bench/bench_bodies [--spacing 0.015] [--steps 40] [--pairs 3]
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <CLI/CLI.hpp>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

struct Options
{
    double spacing = 0.015;
    int steps = 40, warmup = 10, pairs = 3;
    std::string pressure = "tait";
};

LevelSet tank(Real h)
{
    const openvdb::Vec3d lo(-0.3, 0, -0.3), hi(0.3, 1.0, 0.3);
    const openvdb::Vec3d outerLo = lo - openvdb::Vec3d(4 * h), outerHi(0.3 + 4 * h, 0.5, 0.3 + 4 * h);
    auto sdf = [&](const openvdb::Vec3d& x) {
        return std::max(boxSignedDistance(x, outerLo, outerHi), -boxSignedDistance(x, lo, hi));
    };
    return makeLevelSet(levelSetFromSdf(sdf, Aabb{Vec3(outerLo), Vec3(outerHi)}, h / 2), "tank");
}

/// The box at its draft (5 cm below the surface at 25 cm) and the water around it.
const openvdb::Vec3d BOX_LO(-0.1, 0.2, -0.1), BOX_HI(0.1, 0.3, 0.1);

LevelSet box(Real h)
{
    return makeLevelSet(makeBoxLevelSet(Vec3(BOX_LO), Vec3(BOX_HI), h / 2), "box");
}

LevelSet water(Real h)
{
    const openvdb::Vec3d lo(-0.3, 0, -0.3), hi(0.3, 0.25, 0.3);
    auto sdf = [&](const openvdb::Vec3d& x) {
        return std::max(boxSignedDistance(x, lo, hi), -boxSignedDistance(x, BOX_LO, BOX_HI));
    };
    return makeLevelSet(levelSetFromSdf(sdf, Aabb{Vec3(lo), Vec3(hi)}, h / 2), "water");
}

/// Seconds per step of one run, with the box dynamic or keyed.
double secondsPerStep(const Options& opt, bool dynamic)
{
    GhostSettings s;
    s.spacing = Real(opt.spacing);
    s.stiffness = Real(20000);
    s.pressure = opt.pressure == "dfsph" ? PressureModel::Dfsph : PressureModel::Tait;
    GhostSolver solver(s);
    const Real h = s.spacing;
    solver.addSolid(tank(h));
    if (dynamic) {
        DynamicSolid spec;
        spec.density = 500;
        solver.addDynamicSolid(box(h), spec);
    } else {
        solver.addMovingSolid(box(h), [](double t) {
            RigidTransform xf;
            xf.translation = Vec3(0, Real(0.01 * std::sin(2 * M_PI * t)), 0);
            xf.translationRate = Vec3(0, Real(0.02 * M_PI * std::cos(2 * M_PI * t)), 0);
            xf.hasRates = true;
            return xf;
        });
    }
    solver.addLiquid(water(h));
    const Real fixed = Real(0.2) * h / s.soundSpeed();
    auto dt = [&] { return s.pressure == PressureModel::Dfsph ? solver.stableTimeStep() : fixed; };
    for (int k = 0; k < opt.warmup; ++k) solver.step(dt());
    const PressureSolveStats before = solver.pressureSolveStats();
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < opt.steps; ++k) solver.step(dt());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // The solves' iterations per step: a dynamic box moves otherwise than the keyed one, and
    // DFSPH's cost follows its iterations.
    const PressureSolveStats& after = solver.pressureSolveStats();
    const double iterations = double(after.densityIterations + after.divergenceIterations
                                     - before.densityIterations - before.divergenceIterations)
                              / opt.steps;
    std::printf("  %s: %zu liquid, %.2f ms/step, %.1f solve iterations/step\n",
                dynamic ? "dynamic" : "keyed  ", solver.count(ParticleKind::Liquid),
                1e3 * seconds / opt.steps, iterations);
    return seconds / opt.steps;
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

} // namespace

int main(int argc, char** argv)
{
    openvdb::initialize();
    Options opt;
    CLI::App app("Dynamic solid against a keyed one: time per step");
    app.add_option("--spacing", opt.spacing, "particle spacing h (m)")->check(CLI::Range(0.005, 0.05));
    app.add_option("--steps", opt.steps, "measured steps")->check(CLI::Range(1, 100000));
    app.add_option("--warmup", opt.warmup, "steps before the measurement")->check(CLI::Range(1, 100000));
    app.add_option("--pairs", opt.pairs, "interleaved pairs of runs")->check(CLI::Range(1, 100));
    app.add_option("--pressure", opt.pressure, "tait or dfsph")->check(CLI::IsMember({"tait", "dfsph"}));
    CLI11_PARSE(app, argc, argv);
    std::vector<double> keyed, dynamic;
    for (int p = 0; p < opt.pairs; ++p) {
        keyed.push_back(secondsPerStep(opt, false));
        dynamic.push_back(secondsPerStep(opt, true));
    }
    const double k = median(keyed), d = median(dynamic);
    std::printf("%s, h = %.3f m: keyed %.2f ms/step, dynamic %.2f ms/step, dynamic / keyed %.3f\n",
                opt.pressure.c_str(), opt.spacing, 1e3 * k, 1e3 * d, d / k);
    return 0;
}
