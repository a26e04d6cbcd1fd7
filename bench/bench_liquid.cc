/// @file   bench_liquid.cc
/// @brief  Liquid solver scene benchmark ([SB12] Sec. 5, Table 1): time per step, particle counts,
///         the per-phase breakdown, the air-resampling share, neighbours and the cost per
///         particle-neighbour pair, for Ghost SPH and the Basic SPH baseline.
/// @details Two scenes, both with a solid and free surfaces:
///            - dam break: a liquid block of aspect 1 x 2 x 1 in one corner of an open-top tank
///              (a solid made by levelSetFromSdf from max(outer box, -inner box), the inner box
///              reaching above the top); the spacing h is chosen so that the block holds about
///              `--liquid` particles (the sampler packs about 0.75 particles per h^3);
///            - sphere: a liquid sphere of about `--sphere-liquid` particles (h = 0.01 m) falling
///              at 1.5 m/s onto a solid sphere, 2 h above it at the start.
///          The liquid is sampled once per scene (the Ghost solver's addLiquid) and the same
///          positions are given to the Basic solver, so both methods start from identical liquid.
///          Each method then runs `--warmup` steps (the first one includes the initial air layer
///          and the mass scaling, timed on its own), resets the solver's PhaseTimings and runs
///          `--steps` measured steps, each timed with std::chrono around GhostSolver::step().
///          dt is fixed at 1 / (30 * 20) s ([SB12]: 20 steps per frame at 30 frames/s) unless
///          `--cfl` is given. Basic SPH blows up at that dt in both scenes
///          (bench/history/diary-2026-11.md); its per-step cost comes from
///          `--method basic --cfl 0.4`. Plain main (no Google Benchmark): one scene run takes a
///          minute, not a loop to repeat. Results and how they were taken: bench/RESULTS.md.
///
///          Run: build/bench/bench_liquid [--liquid 100000] [--steps 30] [--warmup 20]
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/ghost/Whitewater.h>
#include <ghostfx/sph/DomainDecomposition.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>

#include <CLI/CLI.hpp>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <set>
#include <string>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

/// Particles per h^3 the [SB12] sampler produces after relaxation (README, bench_sampler.cc).
constexpr double SAMPLES_PER_CUBIC_SPACING = 0.75;
/// [SB12] Table 1 and Sec. 5: 20 steps per frame at 30 frames/s.
constexpr double PAPER_DT = 1.0 / (30.0 * 20.0);

struct Options
{
    double damLiquid = 100000;     ///< dam break: target liquid particle count
    double tankFloor = 1;          ///< dam break: tank floor area as a multiple of the default
    double sphereLiquid = 20000;   ///< sphere scene: target liquid particle count
    double sphereSpacing = 0.01;   ///< sphere scene: h (m)
    int steps = 30;                ///< measured steps
    int warmup = 20;               ///< steps before the measurement (>= 1)
    double cfl = 0;                ///< > 0: CFL-limited dt with this number instead of PAPER_DT
    double stiffness = 0;          ///< > 0: Tait k (Pa) instead of the default ([SB12]: 2000)
    double viscosity = 0;          ///< kinematic viscosity nu (m^2/s), no-slip walls when > 0
    double viscosityError = 0;     ///< > 0: settings.viscosity_error instead of the default
    bool whitewater = false;       ///< also time ghost::Whitewater after each measured step
    double kernelSupport = 0;      ///< > 0: kernel support / h instead of the default ([SB12]: 3)
    double shifting = -1;          ///< >= 0: particle shifting coefficient instead of the default
    std::string airWeights;        ///< "matched" or "complete" instead of the default
    double lennardJones = 0;       ///< > 0: Basic SPH wall strength D (m^2/s^2) instead of 5 g H
    int threads = 0;               ///< TBB threads, 0 = all
    std::string scenes = "all";    ///< dam, sphere, all or splish_dam
    std::string methods = "both";  ///< ghost, basic or both
    std::string pressure = "tait"; ///< Ghost SPH pressure model: tait or dfsph
    bool divergenceWarmStart = true; ///< DFSPH: the divergence solve starts from its last pressure
    std::string wallPressure = "mirror"; ///< DFSPH: settings.dfsph.wall_pressure
    std::string airDensity = "full";     ///< DFSPH: settings.dfsph.air_density
    std::string airResampling = "step";  ///< DFSPH: settings.dfsph.air_resampling
    double densityRelaxation = -1;       ///< DFSPH: dfsph.density_relaxation (< 0: default)
    std::uint64_t seed = 1;
    bool halo = false;  ///< print the halos of domain decompositions of the state
    bool trace = false; ///< print one line per measured step (stderr)
};

double seconds(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Scenes ------------------------------------------------------------------------------------------

Vec3 toVec3(const openvdb::Vec3d& x) { return Vec3(Real(x.x()), Real(x.y()), Real(x.z())); }

struct Scene
{
    std::string name;
    std::string description;
    Real spacing; ///< h (m)
    LevelSet solid;
    LevelSet liquid;
    Vec3 liquidVelocity; ///< initial liquid velocity (m/s)
    Aabb container;      ///< liquid outside this box counts as escaped
};

/// The walls of a box tank: the solid max(outer box, -cut box) (m). A cut box reaching above
/// the outer one leaves the tank open at the top.
struct Tank
{
    openvdb::Vec3d outerLo, outerHi, cutLo, cutHi;
};

/// A liquid block [blockLo, blockHi] (m) at rest in `tank`, spacing h (m), voxels h / 2; liquid
/// outside the tank's outer box padded by 2 h counts as escaped.
Scene blockInTank(std::string name, std::string description, double h, const Tank& tank,
                  const char* tankName, const Vec3& blockLo, const Vec3& blockHi)
{
    const double voxel = 0.5 * h;
    auto tankSdf = [=](const openvdb::Vec3d& x) {
        return std::max(boxSignedDistance(x, tank.outerLo, tank.outerHi),
                        -boxSignedDistance(x, tank.cutLo, tank.cutHi));
    };
    const Aabb outer{toVec3(tank.outerLo), toVec3(tank.outerHi)};
    return Scene{std::move(name),
                 std::move(description),
                 Real(h),
                 makeLevelSet(levelSetFromSdf(tankSdf, outer, Real(voxel)), tankName),
                 makeLevelSet(makeBoxLevelSet(blockLo, blockHi, Real(voxel)), "water"),
                 Vec3(0),
                 outer.padded(Real(2 * h))};
}

/// Dam break: liquid block 0.4 x 0.8 x 0.4 m (scaled with h) in the corner of an open-top tank
/// whose inside is 3 x 1.25 x 1 block (1.2 x 1.0 x 0.4 m), walls one kernel radius (3 h) thick:
/// the ghost-solid band is one kernel radius deep ([SB12] Sec. 4.4), so thicker walls would add
/// particles no liquid ever sees. The block is flush with the walls and the floor; addLiquid drops
/// the samples closer than h / 2 to the solid (the layer on the shared faces).
/// `floorFactor` scales the tank's floor area (its length; the block still spans the whole
/// depth between the front and back walls, so the liquid and its free surface are the same):
/// the liquid-speed check that a step costs what its liquid costs, not its tank.
Scene damBreak(double targetLiquid, double floorFactor)
{
    const double blockX = 0.4, blockY = 0.8, blockZ = 0.4; // m
    const double h = std::cbrt(SAMPLES_PER_CUBIC_SPACING * blockX * blockY * blockZ / targetLiquid);
    const double wall = 3 * h;
    const openvdb::Vec3d innerLo(0, 0, 0), innerHi(3 * blockX * floorFactor, 1.25 * blockY, blockZ);
    const openvdb::Vec3d outerLo = innerLo - openvdb::Vec3d(wall);
    const openvdb::Vec3d outerHi(innerHi.x() + wall, innerHi.y(), innerHi.z() + wall);
    // The inner box reaches above the top, so the tank is open there.
    const openvdb::Vec3d cutHi(innerHi.x(), innerHi.y() + 1, innerHi.z());
    char text[256];
    std::snprintf(text, sizeof(text),
                  "block %.2f x %.2f x %.2f m in an open tank %.2f x %.2f x %.2f m (inside), "
                  "walls %.4f m, h = %.5f m",
                  blockX, blockY, blockZ, innerHi.x(), innerHi.y(), innerHi.z(), wall, h);
    return blockInTank(floorFactor == 1 ? "dam_break" : msg("dam_break_floor", floorFactor), text,
                       h, Tank{outerLo, outerHi, innerLo, cutHi}, "tank", Vec3(0),
                       Vec3(Real(blockX), Real(blockY), Real(blockZ)));
}

/// SPlisHSPlasH's dam break (its `DamBreakModel` scene, as `shared/anchors/splishsplash.md`
/// scales it to 104k particles): a 1 m cube of liquid 5 cm from the floor and the left wall,
/// centred between the front and back walls, in a closed box 4 x 3 x 1.5 m (inside). The same
/// scene as the comparator's, so wall seconds per simulated second compare (its particles are
/// twice as far apart as those of `damBreak` at the same count, and its steps twice as long).
Scene splishDamBreak(double targetLiquid)
{
    const double h = std::cbrt(SAMPLES_PER_CUBIC_SPACING * 1.0 / targetLiquid);
    const double wall = 3 * h;
    const openvdb::Vec3d innerLo(0, 0, 0), innerHi(4, 3, 1.5);
    const Vec3 blockLo(Real(0.05), Real(0.05), Real(0.25));
    char text[256];
    std::snprintf(text, sizeof(text),
                  "SPlisHSPlasH's DamBreakModel: 1 m cube at (0.05, 0.05, 0.25) m in a closed box "
                  "4 x 3 x 1.5 m (inside), walls %.4f m, h = %.5f m",
                  wall, h);
    const Tank box{innerLo - openvdb::Vec3d(wall), innerHi + openvdb::Vec3d(wall), innerLo,
                   innerHi};
    return blockInTank("splish_dam_break", text, h, box, "box", blockLo, blockLo + Vec3(1));
}

/// Liquid sphere (radius from the target count) 2 h above a solid sphere of radius 0.2 m, its
/// centre 0.05 m off the solid's axis, falling at 1.5 m/s (as if dropped from 11 cm higher).
Scene sphereDrop(double targetLiquid, double h)
{
    const double volume = targetLiquid / SAMPLES_PER_CUBIC_SPACING * h * h * h;
    const double radius = std::cbrt(3 * volume / (4 * openvdb::math::pi<double>()));
    const double solidRadius = 0.2, voxel = 0.5 * h;
    const Vec3 centre(Real(0.05), Real(solidRadius + radius + 2 * h), 0);
    char text[256];
    std::snprintf(text, sizeof(text),
                  "liquid sphere r = %.3f m at (%.2f, %.3f, 0) m, v = (0, -1.5, 0) m/s, onto a "
                  "solid sphere r = %.2f m at the origin, h = %.5f m",
                  radius, double(centre[0]), double(centre[1]), solidRadius, h);
    Scene s{"sphere_drop",
            text,
            Real(h),
            makeLevelSet(makeSphereLevelSet(Vec3(0), Real(solidRadius), Real(voxel)), "ball"),
            makeLevelSet(makeSphereLevelSet(centre, Real(radius), Real(voxel)), "drop"),
            Vec3(0, Real(-1.5), 0),
            Aabb{Vec3(Real(-1)), Vec3(Real(1))}};
    return s;
}

// Running one method -----------------------------------------------------------------------------

struct RunResult
{
    std::string scene;
    Method method = Method::Ghost;
    PressureModel pressure = PressureModel::Tait;
    PressureSolveStats solve; ///< DFSPH iterations over the measured steps
    double viscosityIterations = 0, viscositySeconds = 0; ///< per measured step
    double whitewaterSeconds = 0;  ///< per measured step: the snapshot and Whitewater::step
    std::size_t whitewaterMade = 0, whitewaterLeft = 0;
    bool ok = false;
    std::string error;
    std::size_t liquid = 0, air = 0, solid = 0;                  ///< at the end of the measurement
    double solidSampling = 0, liquidSampling = 0, firstStep = 0; ///< s
    double meanStep = 0, minStep = 0, maxStep = 0, medianStep = 0; ///< s, chrono around step()
    double dt = 0;                                                 ///< mean dt (s)
    PhaseTimings phases;
    double meanNeighbors = 0;
    double maxSpeed = 0, maxDensityRatio = 0;       ///< at the end (m/s, rho / rho0)
    double spacing = 0;                             ///< h (m)
    Vec3 fastest{0};                                ///< where the fastest liquid particle is
    double fastestPhi = 0, fastestDensityRatio = 0; ///< its distance to the solid, rho / rho0
    std::size_t escaped = 0, insideSolid = 0;
    GhostSolver::MemoryUse memory; ///< what the solver holds at the end
    int steps = 0;                 ///< measured steps completed
};

/// The halos that a domain decomposition of the solver's present state would exchange, for
/// slabs and recursive bisection over 2 to 1,024 parts (the scaling model of
/// bench/history/diary-2026-11.md, "One simulation over many ranks"). A part owns the liquid and
/// air in its region (what it computes); its halo is the liquid and air of other parts within a
/// support radius R of its region (copies it receives every step); its solid particles are those in
/// or within R of its region (sampled locally, never exchanged).
/// One line per step (--trace): what to look at when a run goes wrong at some step.
void traceStep(const GhostSolver& solver, Real dt, double wall)
{
    const ParticleSet& p = solver.particles();
    const Real rho0 = solver.settings().restDensity;
    double vmax = 0, rmax = 0;
    std::size_t fastest = 0, air = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::GhostAir) ++air;
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        const double v = double(p.velocities()[i].length());
        if (v > vmax) vmax = v, fastest = i;
        rmax = std::max(rmax, double(p.densities()[i] / rho0));
    }
    const PressureSolveStats& s = solver.pressureSolveStats();
    const Vec3 x = p.size() ? p.positions()[fastest] : Vec3(0);
    // The fastest particle's density by the kind of neighbour (at the positions after the
    // step, so the parts need not add up to the density the step used).
    const CubicSplineKernel kernel(solver.settings().supportRadius());
    double parts[3] = {0, 0, 0}; // liquid, air, solid
    auto add = [&](const ParticleSet& set) {
        for (std::size_t j = 0; j < set.size(); ++j) {
            const Real w = kernel.W((set.positions()[j] - x).length());
            if (w == Real(0)) continue;
            const int k = set.kinds()[j] == ParticleKind::Liquid     ? 0
                          : set.kinds()[j] == ParticleKind::GhostAir ? 1
                                                                     : 2;
            parts[k] += double(set.masses()[j] * w / rho0);
        }
    };
    add(p);
    add(solver.solidParticles());
    std::fprintf(stderr,
                 "trace step %llu t %.5f dt %.3e wall %.3f s | vmax %.3f at (%.3f %.3f %.3f) "
                 "rho/rho0 %.3f (liquid %.3f, air %.3f, solid %.3f) | max rho/rho0 %.3f | dfsph "
                 "%d density (mean %.2e, largest %.2e) %d divergence (mean %.2e, largest %.2e) "
                 "| air %zu\n",
                 (unsigned long long)solver.stepCount(), double(solver.time()), double(dt), wall,
                 vmax, double(x[0]), double(x[1]), double(x[2]),
                 p.size() ? double(p.densities()[fastest] / rho0) : 0.0, parts[0], parts[1],
                 parts[2], rmax, s.lastDensityIterations, s.lastDensityError,
                 s.lastLargestDensityError, s.lastDivergenceIterations, s.lastDivergenceError,
                 s.lastLargestDivergenceError, air);
}

void printHalo(const GhostSolver& solver, const std::string& when)
{
    const ParticleSet& p = solver.particles();
    std::vector<Vec3> fluid;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const ParticleKind k = p.kinds()[i];
        if (k == ParticleKind::Liquid || k == ParticleKind::GhostAir)
            fluid.push_back(p.positions()[i]);
    }
    const ParticleSet solidSet = solver.solidParticles();
    const std::vector<Vec3>& solids = solidSet.positions();
    const Real R = solver.settings().supportRadius();
    std::printf("\n  halo %s: %zu liquid and air, %zu solid particles, R = %.5f m\n"
                "| scheme | parts | owned per part | imbalance | halo / owned (all parts) | "
                "halo / owned (worst part) | parts sending to a part (mean / max) | solid per "
                "part / all solid |\n|---|---|---|---|---|---|---|---|\n",
                when.c_str(), fluid.size(), solids.size(), double(R));
    for (const DecompositionScheme scheme :
         {DecompositionScheme::Slabs, DecompositionScheme::Bisection}) {
        for (int parts = 2; parts <= 1024 && std::size_t(parts) <= fluid.size(); parts *= 2) {
            const DomainDecomposition d = DomainDecomposition::balanced(fluid, parts, scheme);
            std::vector<std::size_t> owned(std::size_t(parts), 0), halo(owned), solid(owned);
            std::vector<std::set<int>> sources(owned.size());
            for (const Vec3& x : fluid) {
                const int own = d.owner(x);
                ++owned[std::size_t(own)];
                d.forEachHaloPart(x, R, [&](int q) {
                    ++halo[std::size_t(q)];
                    sources[std::size_t(q)].insert(own);
                });
            }
            for (const Vec3& x : solids) {
                ++solid[std::size_t(d.owner(x))];
                d.forEachHaloPart(x, R, [&](int q) { ++solid[std::size_t(q)]; });
            }
            double totalHalo = 0, totalOwned = 0, worst = 0, totalSolid = 0, sourceSum = 0;
            std::size_t sourceMax = 0;
            for (std::size_t k = 0; k < owned.size(); ++k) {
                totalHalo += double(halo[k]);
                totalOwned += double(owned[k]);
                totalSolid += double(solid[k]);
                if (owned[k] > 0) worst = std::max(worst, double(halo[k]) / double(owned[k]));
                sourceSum += double(sources[k].size());
                sourceMax = std::max(sourceMax, sources[k].size());
            }
            std::printf("| %s | %d | %.0f | %.3f | %.3f | %.3f | %.1f / %zu | %.0f / %.3f |\n",
                        scheme == DecompositionScheme::Slabs ? "slabs" : "bisection", parts,
                        totalOwned / parts, DomainDecomposition::imbalance(owned),
                        totalHalo / totalOwned, worst, sourceSum / parts, sourceMax,
                        totalSolid / parts,
                        solids.empty() ? 0.0 : totalSolid / parts / double(solids.size()));
        }
    }
}

/// Warm up and measure `solver` (its solid already added). The liquid is `liquidPositions`
/// (sampled once per scene) unless the solver already holds liquid. A NumericalError (blow-up)
/// ends the run and is recorded in `out`; the state at the end is recorded either way.
void runMethod(const Scene& scene, Method method, const std::vector<Vec3>& liquidPositions,
               GhostSolver& solver, const Options& opt, RunResult& out)
{
    out.scene = scene.name;
    out.spacing = scene.spacing;
    out.method = method;
    out.pressure = solver.settings().pressure;
    double sum = 0, lo = 1e30, hi = 0, nbrs = 0, simulated = 0;
    std::vector<double> times;
    bool measuring = false;
    ViscositySolveStats viscosityAtStart;
    Whitewater white{WhitewaterSettings()};
    double whiteSum = 0;
    try {
        if (solver.count(ParticleKind::Liquid) == 0) {
            solver.addLiquidParticles(liquidPositions, scene.liquidVelocity);
        }
        // DFSPH steps are bound by the flow speed: always CFL steps (its point).
        const bool cflSteps = opt.cfl > 0 || solver.settings().pressure == PressureModel::Dfsph;
        auto nextDt = [&]() { return cflSteps ? solver.stableTimeStep() : Real(PAPER_DT); };

        // Warm-up; the first step also builds the air layer and scales the mass (Sec. 4.6).
        auto t0 = std::chrono::steady_clock::now();
        solver.step(nextDt());
        out.firstStep = seconds(t0);
        if (opt.halo) printHalo(solver, "after the first step (the liquid at rest, with its air)");
        for (int s = 1; s < opt.warmup; ++s) solver.step(nextDt());

        solver.resetTimings();
        viscosityAtStart = solver.viscositySolveStats();
        measuring = true;
        // As a run's frames do: the reported pressure (DFSPH) on the steps that end a frame.
        const double frame = 1.0 / double(solver.settings().frameRate);
        for (int s = 0; s < opt.steps; ++s) {
            const Real dt = nextDt();
            const double t = solver.time();
            const bool endsFrame = std::floor((t + double(dt)) / frame) > std::floor(t / frame);
            t0 = std::chrono::steady_clock::now();
            solver.step(dt, endsFrame);
            const double elapsed = seconds(t0);
            simulated += double(dt);
            sum += elapsed;
            lo = std::min(lo, elapsed);
            hi = std::max(hi, elapsed);
            times.push_back(elapsed);
            nbrs += solver.meanNeighbors();
            ++out.steps;
            if (opt.trace) traceStep(solver, dt, elapsed);
            if (opt.whitewater) {
                t0 = std::chrono::steady_clock::now();
                const GhostSettings& gs = solver.settings();
                white.step(LiquidSnapshot::fromParticles(solver.particles(), gs.spacing,
                                                         gs.supportFactor, gs.gravity),
                           dt);
                whiteSum += seconds(t0);
            }
        }
        out.ok = true;
    } catch (const NumericalError& e) {
        out.error = e.what();
    }
    if (measuring && out.steps > 0) {
        // A blown-up run keeps the timings of the steps it completed (its PhaseTimings also hold
        // the phases of the step that failed, but not that step's total).
        out.meanStep = sum / out.steps;
        out.minStep = lo;
        out.maxStep = hi;
        std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
        out.medianStep = times[times.size() / 2];
        out.dt = simulated / out.steps;
        out.meanNeighbors = nbrs / out.steps;
        out.phases = solver.timings();
        out.solve = solver.pressureSolveStats();
        const ViscositySolveStats& v = solver.viscositySolveStats();
        out.viscosityIterations = double(v.iterations - viscosityAtStart.iterations) / out.steps;
        out.viscositySeconds = (v.seconds - viscosityAtStart.seconds) / out.steps;
        out.whitewaterSeconds = whiteSum / out.steps;
        out.whitewaterMade = std::size_t(white.made());
        out.whitewaterLeft = white.size();
    }

    if (opt.halo && out.steps > 0) {
        printHalo(solver, msg("at the end (t = ", solver.time(), " s, after ", solver.stepCount(),
                              " steps)"));
    }
    const ParticleSet& p = solver.particles();
    const Real rho0 = solver.settings().restDensity;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        const Vec3& x = p.positions()[i];
        const double speed = p.velocities()[i].length();
        if (speed > out.maxSpeed) {
            out.maxSpeed = speed;
            out.fastest = x;
            out.fastestPhi = scene.solid.phi(x);
            out.fastestDensityRatio = p.densities()[i] / rho0;
        }
        out.maxDensityRatio = std::max(out.maxDensityRatio, double(p.densities()[i] / rho0));
        if (!scene.container.contains(x)) ++out.escaped;
        if (scene.solid.phi(x) < -Real(0.01) * scene.spacing) ++out.insideSolid;
    }
    out.liquid = solver.count(ParticleKind::Liquid);
    out.air = solver.count(ParticleKind::GhostAir);
    out.solid =
        solver.count(method == Method::Ghost ? ParticleKind::GhostSolid : ParticleKind::Boundary);
    out.memory = solver.memoryUse();
}

double percent(double part, double whole) { return whole > 0 ? 100 * part / whole : 0; }

void printRun(const RunResult& r)
{
    std::printf("\n--- %s, %s, %s pressure ---\n", r.scene.c_str(), methodName(r.method),
                pressureName(r.pressure));
    if (!r.ok) std::printf("  FAILED: %s\n", r.error.c_str());
    std::printf("  particles: liquid %zu, ghost air %zu (%.0f %%), %s %zu (%.0f %%), total %zu\n",
                r.liquid, r.air, percent(double(r.air), double(r.liquid)),
                r.method == Method::Ghost ? "ghost solid" : "boundary", r.solid,
                percent(double(r.solid), double(r.liquid)), r.liquid + r.air + r.solid);
    std::printf("  set-up: solid sampling %.2f s, liquid sampling %.2f s, first step (air layer, "
                "mass scaling) %.2f s\n",
                r.solidSampling, r.liquidSampling, r.firstStep);
    const double all = double(r.liquid + r.air + r.solid);
    const GhostSolver::MemoryUse& m = r.memory;
    const double lists = double(m.lists + m.solidLists);
    std::printf("  memory: %.1f MB, %.1f bytes per particle (particles, solid blocks, grids, "
                "scratch %.1f + the step's neighbour lists %.1f)\n",
                double(m.total()) / 1e6, double(m.total()) / all, (double(m.total()) - lists) / all,
                lists / all);
    auto mb = [](std::size_t bytes) { return double(bytes) / 1e6; };
    std::printf("    liquid and air: particles %.1f MB, grid %.1f, lists %.1f; solids: particles "
                "%.1f, grids %.1f, lists from liquid %.1f; step arrays %.1f\n",
                mb(m.particles), mb(m.grid), mb(m.lists), mb(m.solidParticles), mb(m.solidGrids),
                mb(m.solidLists), mb(m.stepArrays));
    std::printf("  state at the end: max liquid speed %.3f m/s, max rho/rho0 %.3f, %zu liquid "
                "outside the container, %zu inside the solid\n",
                r.maxSpeed, r.maxDensityRatio, r.escaped, r.insideSolid);
    std::printf("  fastest liquid particle: at (%.4f, %.4f, %.4f) m, %.2f h from the solid, "
                "rho/rho0 %.3f\n",
                double(r.fastest[0]), double(r.fastest[1]), double(r.fastest[2]),
                r.fastestPhi / double(r.spacing), r.fastestDensityRatio);
    if (r.steps == 0) return;
    if (!r.ok) {
        // The phases of the failed step are in r.phases but its total is not: no breakdown.
        std::printf("  step: mean %.1f ms over the %d measured steps completed before the "
                    "blow-up\n",
                    1e3 * r.meanStep, r.steps);
        return;
    }
    const PhaseTimings& t = r.phases;
    const double n = double(t.steps);
    std::printf("  step: mean %.1f ms (median %.1f, min %.1f, max %.1f = %.2f x median) over %d "
                "measured steps, dt = %.6g s; solver total %.1f ms/step\n",
                1e3 * r.meanStep, 1e3 * r.medianStep, 1e3 * r.minStep, 1e3 * r.maxStep,
                r.maxStep / r.medianStep, r.steps, r.dt, 1e3 * t.total / n);
    const double other =
        t.total - t.neighborsAndDensity - t.pressureForce - t.xsphAndBoundary - t.airResampling;
    const struct
    {
        const char* name;
        double s;
    } rows[] = {
        {"neighbours + density", t.neighborsAndDensity},
        {"pressure force", t.pressureForce},
        {"XSPH + boundary", t.xsphAndBoundary},
        {"air resampling", t.airResampling},
        {"other (air fade, solid motion, blow-up check)", other},
    };
    for (const auto& row : rows) {
        std::printf("    %-46s %8.1f ms %6.1f %%\n", row.name, 1e3 * row.s / n,
                    percent(row.s, t.total));
        if (row.s == t.neighborsAndDensity) {
            std::printf("      %-44s %8.1f ms %6.1f %%\n", "of which sort + neighbour search",
                        1e3 * t.sortAndSearch / n, percent(t.sortAndSearch, t.total));
        }
    }
    const double pairs = double(r.liquid) * r.meanNeighbors;
    std::printf("  mean neighbours %.1f; %.2f ns per particle-neighbour pair; %.1f wall s per "
                "simulated s\n",
                r.meanNeighbors, 1e9 * r.meanStep / pairs, r.meanStep / r.dt);
    if (r.viscositySeconds > 0) {
        std::printf("  viscosity: %.1f iterations and %.1f ms per step (%.1f %% of the step)\n",
                    r.viscosityIterations, 1e3 * r.viscositySeconds,
                    percent(r.viscositySeconds, r.meanStep));
    }
    if (r.whitewaterSeconds > 0) {
        std::printf("  whitewater: %.1f ms per step (%.1f %% of the step), %zu made, %zu at the end\n",
                    1e3 * r.whitewaterSeconds, percent(r.whitewaterSeconds, r.meanStep),
                    r.whitewaterMade, r.whitewaterLeft);
    }
    if (r.pressure == PressureModel::Dfsph) {
        const PressureSolveStats& st = r.solve;
        std::printf("  DFSPH: %.1f density + %.1f divergence iterations per step, last errors "
                    "%.2e / %.2e, largest of one particle %.2e / %.2e, %llu unconverged "
                    "solves\n",
                    double(st.densityIterations) / double(st.steps),
                    double(st.divergenceIterations) / double(st.steps), st.lastDensityError,
                    st.lastDivergenceError, st.largestDensityError, st.largestDivergenceError,
                    static_cast<unsigned long long>(st.unconverged));
    }
}

std::vector<RunResult> runScene(const Scene& scene, const Options& opt)
{
    std::printf("\n=== scene %s: %s\n", scene.name.c_str(), scene.description.c_str());
    std::fflush(stdout);
    GhostSettings settings;
    settings.spacing = scene.spacing;
    settings.seed = opt.seed;
    if (opt.cfl > 0) settings.cflNumber = Real(opt.cfl);
    if (opt.stiffness > 0) settings.stiffness = Real(opt.stiffness);
    if (opt.viscosity > 0) {
        settings.viscosity = Real(opt.viscosity);
        settings.solidSlip = ghost::SolidSlip::NoSlip;
    }
    if (opt.viscosityError > 0) settings.viscosityError = Real(opt.viscosityError);
    if (opt.kernelSupport > 0) settings.supportFactor = Real(opt.kernelSupport);
    if (opt.shifting >= 0) settings.shiftingCoefficient = Real(opt.shifting);
    if (!opt.airWeights.empty()) {
        settings.airWeights =
            opt.airWeights == "matched" ? AirWeights::Matched : AirWeights::Complete;
    }
    if (opt.lennardJones > 0) settings.lennardJonesStrength = Real(opt.lennardJones);
    settings.dfsph.divergenceWarmStart = opt.divergenceWarmStart;
    if (opt.densityRelaxation > 0) settings.dfsph.densityRelaxation = Real(opt.densityRelaxation);
    settings.dfsph.wallPressure = opt.wallPressure == "own"
                                      ? ghost::DfsphSettings::WallPressure::Own
                                      : ghost::DfsphSettings::WallPressure::Mirror;
    settings.dfsph.airDensity = opt.airDensity == "fill" ? ghost::DfsphSettings::AirDensity::Fill
                                                         : ghost::DfsphSettings::AirDensity::Full;
    settings.dfsph.airResampling = opt.airResampling == "step"
                                       ? ghost::DfsphSettings::AirResampling::Step
                                       : ghost::DfsphSettings::AirResampling::Time;
    const PressureModel pressure = pressureFromName(opt.pressure);

    std::vector<RunResult> results;
    std::vector<Vec3> liquid;
    double liquidSampling = 0;
    for (const Method method : {Method::Ghost, Method::Basic}) {
        if (opt.methods != "both" && opt.methods != methodName(method)) continue;
        settings.method = method;
        settings.pressure = method == Method::Ghost ? pressure : PressureModel::Tait;
        GhostSolver solver(settings);
        RunResult r;
        auto t0 = std::chrono::steady_clock::now();
        solver.addSolid(scene.solid);
        r.solidSampling = seconds(t0);
        if (liquid.empty()) {
            t0 = std::chrono::steady_clock::now();
            solver.addLiquid(scene.liquid, scene.liquidVelocity);
            liquidSampling = seconds(t0);
            const ParticleSet& p = solver.particles();
            for (std::size_t i = 0; i < p.size(); ++i) {
                if (p.kinds()[i] == ParticleKind::Liquid) liquid.push_back(p.positions()[i]);
            }
            r.liquidSampling = liquidSampling;
        }
        runMethod(scene, method, liquid, solver, opt, r);
        printRun(r);
        std::fflush(stdout);
        results.push_back(r);
    }
    return results;
}

/// A string option that takes one of `choices`, its default shown in the help.
void addChoice(CLI::App& app, const std::string& flag, std::string& value, const std::string& help,
               const std::vector<std::string>& choices)
{
    app.add_option(flag, value, help)->capture_default_str()->check(CLI::IsMember(choices));
}

/// A number option in [lo, hi], its default shown in the help.
template <typename T, typename Bound>
void addBounded(CLI::App& app, const std::string& flag, T& value, const std::string& help, Bound lo,
                Bound hi)
{
    app.add_option(flag, value, help)->capture_default_str()->check(CLI::Range(lo, hi));
}

/// The scene, size and step options.
void addSceneOptions(CLI::App& app, Options& opt)
{
    addBounded(app, "--liquid", opt.damLiquid, "dam break: target liquid particle count", 100.0,
               1e8);
    addBounded(app, "--tank-floor", opt.tankFloor,
               "dam break: tank floor area as a multiple of the default (same liquid)", 1.0, 100.0);
    addBounded(app, "--sphere-liquid", opt.sphereLiquid,
               "sphere scene: target liquid particle count", 100.0, 1e8);
    app.add_option("--sphere-spacing", opt.sphereSpacing, "sphere scene: particle spacing h (m)")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    addBounded(app, "--steps", opt.steps, "measured steps", 1, 1000000);
    addBounded(app, "--warmup", opt.warmup,
               "steps before the measurement (the first includes initialisation)", 1, 1000000);
    app.add_option("--threads", opt.threads, "TBB threads (0 = all)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    addChoice(app, "--scene", opt.scenes,
              "dam, sphere, all (dam and sphere) or splish_dam (SPlisHSPlasH's dam-break "
              "scene, --liquid particles)",
              {"dam", "sphere", "all", "splish_dam"});
    addChoice(app, "--method", opt.methods, "ghost, basic or both", {"ghost", "basic", "both"});
    app.add_option("--seed", opt.seed, "random seed of all sampling")->capture_default_str();
}

/// The solver settings that replace GhostSettings' defaults.
void addSettingOptions(CLI::App& app, Options& opt)
{
    app.add_option("--cfl", opt.cfl,
                   "CFL-limited dt with this number (default: fixed dt = 1/600 s)")
        ->check(CLI::Range(1e-6, 2.0));
    app.add_option("--shifting", opt.shifting,
                   "particle shifting coefficient A (default 2; 0 = off)");
    app.add_option("--air-weights", opt.airWeights,
                   "ghost air weights: matched or complete (default: GhostSettings' default)")
        ->check(CLI::IsMember({"matched", "complete"}));
    app.add_option("--stiffness", opt.stiffness, "Tait stiffness k (Pa; default: [SB12] 2000)")
        ->check(CLI::PositiveNumber);
    app.add_option("--viscosity", opt.viscosity,
                   "kinematic viscosity nu (m^2/s) with no-slip walls (default 0: none)")
        ->check(CLI::Range(0.0, 1e5));
    app.add_flag("--whitewater", opt.whitewater,
                 "also time the whitewater (ghost::Whitewater) after each measured step, apart "
                 "from the step");
    app.add_option("--viscosity-error", opt.viscosityError,
                   "relative residual of the viscosity solve (default: the settings' 1e-4)")
        ->check(CLI::Range(1e-10, 0.1));
    app.add_option("--kernel-support", opt.kernelSupport,
                   "kernel support radius / h (default: [SB12] 3; SPlisHSPlasH uses 2)")
        ->check(CLI::Range(1.5, 6.0));
    app.add_option("--lj", opt.lennardJones,
                   "Basic SPH Lennard-Jones strength D (m^2/s^2; default: 5 g H)")
        ->check(CLI::PositiveNumber);
}

/// The pressure model and DFSPH's settings.
void addPressureOptions(CLI::App& app, Options& opt)
{
    addChoice(app, "--pressure", opt.pressure,
              "Ghost SPH pressure: tait ([SB12]) or dfsph (implicit, CFL steps on the flow "
              "speed)",
              {"tait", "dfsph"});
    app.add_option("--divergence-warm-start", opt.divergenceWarmStart,
                   "DFSPH: the divergence solve starts from its last pressure (settings.dfsph."
                   "divergence_warm_start)")
        ->capture_default_str();
    addChoice(app, "--wall-pressure", opt.wallPressure,
              "DFSPH: ghost solids as the liquid's mirror images or with its own pressure "
              "term (settings.dfsph.wall_pressure)",
              {"mirror", "own"});
    addChoice(app, "--air-density", opt.airDensity,
              "DFSPH: the ghost air's whole mass in the liquid's density, or only what fills "
              "it to rest density (settings.dfsph.air_density)",
              {"full", "fill"});
    addChoice(app, "--air-resampling", opt.airResampling,
              "DFSPH: the ghost air resampled one phase a step, or as far per second as "
              "[SB12]'s steps take it (settings.dfsph.air_resampling)",
              {"step", "time"});
    app.add_option("--density-relaxation", opt.densityRelaxation,
                   "DFSPH: settings.dfsph.density_relaxation (default: DfsphSettings')")
        ->check(CLI::Range(1e-6, 1.0));
}

/// The diagnostics printed beside the measurement.
void addDiagnosticOptions(CLI::App& app, Options& opt)
{
    app.add_flag("--trace", opt.trace,
                 "print a line per measured step to stderr: time, dt, the fastest and densest "
                 "liquid particle, the pressure solve's iterations, the air count");
    app.add_flag("--halo", opt.halo,
                 "print the halos of slab and bisection decompositions into 2-1024 parts, "
                 "after the first step and at the end (the multi-rank scaling model)");
}

/// The command line and the run's threads, Real and time step.
void printHeader(int argc, char** argv, const Options& opt)
{
    std::string command;
    for (int i = 0; i < argc; ++i) command += (i ? " " : "") + std::string(argv[i]);
    std::printf("command: %s\n", command.c_str());
    std::printf("threads: %d, Real = %s, dt = %s; DFSPH reports the pressure on the steps "
                "that end a frame (%g fps), as a run does\n",
                parallel::maxThreads(), sizeof(Real) == 4 ? "float" : "double",
                opt.cfl > 0 ? ("CFL " + std::to_string(opt.cfl)).c_str()
                : opt.pressure == "dfsph"
                    ? "CFL steps at the default number (DFSPH; Basic SPH: 1/600 s fixed)"
                    : "1/600 s (fixed)",
                double(GhostSettings().frameRate));
}

/// Every scene `--scene` names, each with every method `--method` names.
std::vector<RunResult> runScenes(const Options& opt)
{
    std::vector<RunResult> all;
    if (opt.scenes == "splish_dam") {
        for (const RunResult& r : runScene(splishDamBreak(opt.damLiquid), opt)) all.push_back(r);
    }
    if (opt.scenes == "dam" || opt.scenes == "all") {
        for (const RunResult& r : runScene(damBreak(opt.damLiquid, opt.tankFloor), opt))
            all.push_back(r);
    }
    if (opt.scenes == "sphere" || opt.scenes == "all") {
        const Scene scene = sphereDrop(opt.sphereLiquid, opt.sphereSpacing);
        for (const RunResult& r : runScene(scene, opt)) all.push_back(r);
    }
    return all;
}

/// One row of the summary table for a run that completed its measured steps.
void printSummaryRow(const RunResult& r)
{
    const PhaseTimings& t = r.phases;
    const double n = double(t.steps);
    auto cell = [&](double s) {
        char text[64];
        std::snprintf(text, sizeof(text), "%.1f (%.0f %%)", 1e3 * s / n, percent(s, t.total));
        return std::string(text);
    };
    std::printf("| %s | %s | %zu | %zu | %zu | %.1f | %s | %s | %s | %s | %.1f | %.2f | "
                "%.0f |\n",
                r.scene.c_str(), methodName(r.method), r.liquid, r.air, r.solid, 1e3 * r.meanStep,
                cell(t.neighborsAndDensity).c_str(), cell(t.pressureForce).c_str(),
                cell(t.xsphAndBoundary).c_str(), cell(t.airResampling).c_str(), r.meanNeighbors,
                1e9 * r.meanStep / (double(r.liquid) * r.meanNeighbors), r.meanStep / r.dt);
}

/// The summary table of all runs; false if one blew up.
bool printSummary(const std::vector<RunResult>& all)
{
    std::printf("\n| scene | method | liquid | ghost air | ghost solid / boundary | ms/step | "
                "nbr+density | pressure | XSPH+boundary | air resampling | mean nbrs | "
                "ns/pair | wall s / sim s |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    bool failed = false;
    for (const RunResult& r : all) {
        if (!r.ok) failed = true;
        if (r.steps == 0) {
            std::printf("| %s | %s | blew up in the warm-up: see above | | | | | | | | | | |\n",
                        r.scene.c_str(), methodName(r.method));
            continue;
        }
        if (!r.ok) {
            std::printf("| %s | %s (blew up after %d measured steps) | %zu | %zu | %zu | %.1f "
                        "| | | | | %.1f | %.2f | %.0f |\n",
                        r.scene.c_str(), methodName(r.method), r.steps, r.liquid, r.air, r.solid,
                        1e3 * r.meanStep, r.meanNeighbors,
                        1e9 * r.meanStep / (double(r.liquid) * r.meanNeighbors), r.meanStep / r.dt);
            continue;
        }
        printSummaryRow(r);
    }
    return !failed;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"Liquid solver scene benchmark ([SB12] Sec. 5): Ghost SPH and Basic SPH"};
    Options opt;
    addSceneOptions(app, opt);
    addSettingOptions(app, opt);
    addPressureOptions(app, opt);
    addDiagnosticOptions(app, opt);
    CLI11_PARSE(app, argc, argv);

    // A blow-up is a NumericalError, which runScene records; what reaches here ends the run.
    try {
        openvdb::initialize();
        parallel::ThreadLimit limit(opt.threads);
        printHeader(argc, argv, opt);
        return printSummary(runScenes(opt)) ? 0 : 1;
    } catch (const std::exception& e) {
        // ghostfx::Error is what the library reports (status 1); anything else is a bug (2).
        const bool reported = dynamic_cast<const ghostfx::Error*>(&e) != nullptr;
        std::fprintf(stderr, "bench_liquid: %s%s\n",
                     reported ? "error: " : "internal error: ", e.what());
        return reported ? 1 : 2;
    }
}
