/// @file   SampleCommand.cc
/// @brief  `ghostfx sample`: the full [SB12] Sec. 4.5-4.6 pipeline on a built-in level set.
#include "SampleCommand.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/PoissonSampler.h>
#include <ghostfx/sph/SphDensity.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

namespace ghostfx {
namespace cmd {

using namespace sph;

Command addSampleCommand(CLI::App& app)
{
    auto options = std::make_shared<SampleOptions>();
    SampleOptions& o = *options;
    CLI::App* c = app.add_subcommand(
        "sample",
        "Poisson-disk sample a level-set shape ([SB12] Sec. 4.5) and print particle statistics");
    c->add_option("--shape", o.shape, "sphere, box or torus")
        ->check(CLI::IsMember({"sphere", "box", "torus"}))
        ->capture_default_str();
    c->add_option("--size", o.size, "sphere radius, box half edge or torus ring radius (m)")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    c->add_option("--spacing", o.spacing, "particle spacing h (m); Poisson radius r = 0.92 h")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    c->add_option("--voxel-factor", o.voxelFactor, "level-set voxel size / h")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    c->add_option("--band-depth", o.bandDepth,
                  "sample only this deep below the surface (m), as for solids; 0: whole interior")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    c->add_option("--rest-density", o.restDensity, "rest density rho0 (kg/m^3)")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    c->add_option(
         "--relaxation", o.relaxation,
         "volume relaxation: packing (SPH packing, the liquid solver's default) or sb12 ([SB12] "
         "Algorithm 2)")
        ->check(CLI::IsMember({"sb12", "packing"}))
        ->capture_default_str();
    c->add_option("--seed", o.seed, "random seed")->capture_default_str();
    c->add_option("--threads", o.threads, "worker threads (0: all cores)")->capture_default_str();
    return {c, [options] { return runSample(*options); }};
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b)
{
    return std::chrono::duration<double>(b - a).count();
}

/// The level set of `o.shape` (named after it) of size `size` (m) and voxel `voxel` (m).
openvdb::FloatGrid::Ptr makeShapeGrid(const SampleOptions& o, Real size, Real voxel)
{
    openvdb::FloatGrid::Ptr grid;
    if (o.shape == "sphere") grid = makeSphereLevelSet(Vec3(0), size, voxel);
    else if (o.shape == "box") grid = makeBoxLevelSet(Vec3(-size), Vec3(size), voxel);
    else grid = makeTorusLevelSet(Vec3(0), size, size / 3, voxel);
    grid->setName(o.shape);
    return grid;
}

/// The sampler's settings for spacing `h` (m) with the seed, band depth and relaxation of `o`.
PoissonSettings samplerSettings(const SampleOptions& o, Real h)
{
    PoissonSettings settings = PoissonSettings::forSpacing(h);
    settings.seed = o.seed;
    if (o.bandDepth > 0) settings.bandDepth = Real(o.bandDepth);
    settings.volumeRelaxation = o.relaxation == "packing" ? PoissonSettings::Relaxation::Packing
                                                          : PoissonSettings::Relaxation::Sb12;
    return settings;
}

/// The particles of `shape` by the whole pipeline of `settings`, each stage's time printed.
SampleSet sampleTimed(const LevelSet& shape, const PoissonSettings& settings)
{
    PoissonDiskSampler sampler(settings);
    const auto t0 = Clock::now();
    SampleSet s = sampler.sampleSurface(shape);
    const auto t1 = Clock::now();
    sampler.relax(s, shape, settings.surfaceRelaxSweeps, 0);
    const auto t2 = Clock::now();
    sampler.sampleInterior(s, shape);
    const auto t3 = Clock::now();
    sampler.relaxVolume(s, shape);
    const auto t4 = Clock::now();

    std::printf("  surface sampling   %8.3f s  (Algorithm 1, t = %d, e = %g)\n", seconds(t0, t1),
                settings.surfaceAttempts, double(settings.surfaceStep));
    std::printf("  surface relaxation %8.3f s  (Algorithm 2, k = %d, t = %d)\n", seconds(t1, t2),
                settings.surfaceRelaxSweeps, settings.relaxAttempts);
    std::printf("  interior sampling  %8.3f s  (Bridson 2007, t = %d)\n", seconds(t2, t3),
                settings.volumeAttempts);
    if (settings.volumeRelaxation == PoissonSettings::Relaxation::Packing) {
        std::printf("  volume relaxation  %8.3f s  (SPH packing, %d steps)\n", seconds(t3, t4),
                    settings.packingIterations);
    } else {
        std::printf("  volume relaxation  %8.3f s  (Algorithm 2, k = %d, t = %d)\n",
                    seconds(t3, t4), settings.volumeRelaxSweeps, settings.relaxAttempts);
    }
    std::printf("  particles          %8zu     (%zu on the surface), %.0f particles/s\n", s.size(),
                s.surfaceCount(), double(s.size()) / seconds(t0, t4));
    return s;
}

/// Print the nearest-neighbour distances of `s` in units of the Poisson radius `r` (m).
void printSpacing(const SampleSet& s, Real r)
{
    NeighborGrid nnGrid(2 * r);
    nnGrid.build(s.positions);
    double nnSum = 0, nnMin = 1e30;
    for (std::size_t i = 0; i < s.size(); ++i) {
        double d = 1e30;
        nnGrid.forEachNeighbor(Index(i), [&](Index j, const Vec3&, Real rij) {
            if (j != i) d = std::min(d, double(rij));
        });
        if (d < 1e30) {
            nnSum += d;
            nnMin = std::min(nnMin, d);
        }
    }
    std::printf("  nearest neighbour  min %.4f r, mean %.4f r (Poisson-disk: min >= r)\n",
                nnMin / double(r), nnSum / double(s.size()) / double(r));
}

/// Per particle of `s`: whether its kernel support (radius `R`, m) is complete, farther than
/// `R` from every surface sample; empty (all particles count) when none is.
std::vector<std::uint8_t> interiorParticles(const SampleSet& s, Real R)
{
    NeighborGrid surfaceGrid(R);
    std::vector<Vec3> surfacePoints;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (s.onSurface[i]) surfacePoints.push_back(s.positions[i]);
    }
    surfaceGrid.build(surfacePoints);
    std::vector<std::uint8_t> interior(s.size(), 0);
    std::size_t interiorCount = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        bool nearSurface = false;
        surfaceGrid.forEachInRadius(s.positions[i], R,
                                    [&](Index, const Vec3&, Real) { nearSurface = true; });
        interior[i] = !nearSurface;
        interiorCount += interior[i];
    }
    if (interiorCount == 0) {
        std::printf("  mass scaling       no particle deeper than the kernel support (%g m): "
                    "measured over all particles\n",
                    double(R));
        interior.clear();
    }
    return interior;
}

/// Print the [SB12] Sec. 4.6 mass of the particles of `s` (spacing `h`, m) and the density it
/// gives the `interior` ones (all, when empty).
void printMassScaling(const SampleSet& s, const std::vector<std::uint8_t>& interior,
                      const CubicSplineKernel& kernel, const SampleOptions& o)
{
    const Real mass = massForRestDensity(s.positions, kernel, Real(o.restDensity), interior);
    NeighborGrid densityGrid(kernel.supportRadius());
    densityGrid.build(s.positions);
    const std::vector<Real> rho =
        densitySum(s.positions, std::vector<Real>(s.size(), mass), densityGrid, kernel);
    double sum = 0, sum2 = 0, n = 0, lo = 1e30, hi = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (!interior.empty() && !interior[i]) continue;
        sum += rho[i];
        sum2 += double(rho[i]) * rho[i];
        n += 1;
        lo = std::min(lo, double(rho[i]));
        hi = std::max(hi, double(rho[i]));
    }
    const double mean = sum / n;
    std::printf("  mass scaling       m = %.6g kg = %.4f rho0 h^3 ([SB12] Sec. 4.6)\n",
                double(mass), double(mass) / (o.restDensity * std::pow(o.spacing, 3)));
    std::printf("  interior density   %.0f particles: mean %.4f rho0, spread %.2f %%, "
                "range [%.3f, %.3f] rho0\n",
                n, mean / o.restDensity,
                100.0 * std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean, lo / o.restDensity,
                hi / o.restDensity);
}

} // namespace

int runSample(const SampleOptions& o)
{
    parallel::ThreadLimit threadLimit(o.threads);
    const Real h = Real(o.spacing);
    const Real voxel = Real(o.spacing * o.voxelFactor);
    const Real size = Real(o.size);
    if (size < 2 * h) {
        throw ValueError(msg("sample --size = ", o.size,
                             " m: expected at least two particle "
                             "spacings (",
                             2 * o.spacing, " m)"));
    }
    const openvdb::FloatGrid::Ptr grid = makeShapeGrid(o, size, voxel);
    const LevelSet shape = makeLevelSet(grid);
    const PoissonSettings settings = samplerSettings(o, h);
    std::printf("ghostfx sample: %s of size %g m, spacing h = %g m, Poisson radius r = %g m, "
                "voxel %g m (%lld active voxels), %d thread(s)\n",
                o.shape.c_str(), o.size, o.spacing, double(settings.radius), double(voxel),
                static_cast<long long>(grid->activeVoxelCount()), parallel::maxThreads());

    const SampleSet s = sampleTimed(shape, settings);
    printSpacing(s, settings.radius);
    // [SB12] Sec. 4.6 mass scaling, measured on particles whose kernel support is complete.
    const CubicSplineKernel kernel = CubicSplineKernel::fromSpacing(h);
    printMassScaling(s, interiorParticles(s, kernel.supportRadius()), kernel, o);
    return 0;
}

} // namespace cmd
} // namespace ghostfx
