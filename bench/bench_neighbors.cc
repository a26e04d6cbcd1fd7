/// @file   bench_neighbors.cc
/// @brief  Neighbour search: ghostfx::sph::NeighborGrid against OpenVDB's tools::PointIndexGrid,
///         build and one SPH density pass at 1e5 and 1e6 particles.
/// @details Scenario: a cube of particles on a jittered cubic lattice, spacing h = 0.01 m, jitter
///          uniform in +-0.1 h per axis from a fixed seed (the last layer is partial so the count
///          is exact). Kernel: CubicSplineKernel with support radius R = 3 h ([SB12] Sec. 3);
///          mass m = 1000 h^3 (kg), so rho ~ 1000 kg/m^3 inside. Density pass:
///          rho_i = sum_j m_j W(r_ij) over r_ij < R, parallel over i.
///
///          Two particle orders, as a benchmark name component:
///            - `lattice`: generation order (x slowest, z fastest). A sweep through a perfect
///              lattice is an unusually cache- and branch-friendly query order.
///            - `shuffled`: the same particles in a fixed random permutation, as a particle set
///              is after some simulation steps without reordering.
///
///          Before any timing, each scenario computes the density with every search used here
///          and aborts (main prints one line, exit 1) unless all agree per particle to 1e-4
///          relative and the pair counts are equal. Results and conclusions: bench/RESULTS.md.
#include "PointIndexDensity.h"

#include "ghostfx/sph/Kernels.h"
#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/Parallel.h"
#include "ghostfx/sph/ParticleSet.h"
#include "ghostfx/sph/Types.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef GHOSTFX_BUILD_TYPE
#define GHOSTFX_BUILD_TYPE "unknown"
#endif

namespace {

using namespace ghostfx::sph;
using ghostfx::bench::PointIndexDensity;
using ghostfx::bench::PointIndexQuery;
namespace parallel = ghostfx::parallel;

constexpr double SPACING = 0.01;            ///< lattice spacing h (m)
constexpr double JITTER_FRACTION = 0.1;     ///< jitter half-width, fraction of h
constexpr unsigned LATTICE_SEED = 20240611; ///< jitter seed (deterministic scenario)
constexpr unsigned SHUFFLE_SEED = 7;        ///< permutation seed of the `shuffled` order
constexpr double REST_DENSITY = 1000.0;     ///< m = REST_DENSITY h^3 (kg/m^3)
/// Per-particle agreement demanded of the two searches: float sums of about 100 terms added
/// in different orders differ by ~1e-6 relative; 1e-4 leaves room and still catches a missed
/// or doubled neighbour (one neighbour is >= ~0.1% of rho when r < 0.9 R).
constexpr double DENSITY_REL_TOL = 1e-4;

/// PointIndexGrid configuration of the headline BM_PointIndexGrid_* benchmarks: the fastest
/// of the BM_PointIndexGrid_*Variant runs (see bench/history/diary-2026-11.md).
constexpr int PIG_VOXELS_PER_RADIUS = 2; ///< voxel size = R / this
constexpr PointIndexQuery PIG_QUERY = PointIndexQuery::BoxThenDistance;

/// Order of the particles in the arrays handed to the searches.
enum class Order { Lattice, Shuffled };

const char* orderName(Order order) { return order == Order::Lattice ? "lattice" : "shuffled"; }

struct Scenario
{
    Scenario(std::size_t n, Order o)
        : count(n)
        , order(o)
        , kernel(Real(CubicSplineKernel::SB12_SUPPORT_FACTOR * SPACING))
    {}

    std::size_t count;
    Order order;
    CubicSplineKernel kernel;
    std::vector<Vec3> x;              ///< positions (m), in `order`
    std::vector<Real> mass;           ///< m (kg)
    ParticleSet particles;            ///< the same particles as a solver holds them, in `order`
    double neighboursPerParticle = 0; ///< mean |{j : r_ij < R}|, j == i included
};

/// `count` particles on a jittered cubic lattice filling a cube from the origin, in `order`.
std::vector<Vec3> jitteredLattice(std::size_t count, Order order)
{
    const std::size_t side = std::size_t(std::ceil(std::cbrt(double(count)) - 1e-9));
    std::mt19937 rng(LATTICE_SEED);
    std::uniform_real_distribution<double> jitter(-JITTER_FRACTION, JITTER_FRACTION);
    std::vector<Vec3> x;
    x.reserve(count);
    for (std::size_t i = 0; i < side && x.size() < count; ++i) {
        for (std::size_t j = 0; j < side && x.size() < count; ++j) {
            for (std::size_t k = 0; k < side && x.size() < count; ++k) {
                const double px = (double(i) + 0.5 + jitter(rng)) * SPACING;
                const double py = (double(j) + 0.5 + jitter(rng)) * SPACING;
                const double pz = (double(k) + 0.5 + jitter(rng)) * SPACING;
                x.emplace_back(Real(px), Real(py), Real(pz));
            }
        }
    }
    if (order == Order::Shuffled) std::shuffle(x.begin(), x.end(), std::mt19937(SHUFFLE_SEED));
    return x;
}

/// One SPH density pass with the ghostfx grid: rho_i = sum_j m_j W(r_ij), particle i being
/// entry i of the array the grid was built from.
void ghostfxDensity(const NeighborGrid& grid, const CubicSplineKernel& kernel, const Real* mass,
                    Real* rho, std::size_t count)
{
    parallel::forEach(0, count, [&](std::size_t i) {
        Real sum = 0;
        grid.forEachNeighbor(Index(i),
                             [&](Index j, const Vec3&, Real r) { sum += mass[j] * kernel.W(r); });
        rho[i] = sum;
    });
}

/// The same pass through forEachInRadius(x_i, R), for grids whose cells are smaller than R.
void ghostfxDensityInRadius(const NeighborGrid& grid, const Vec3* x,
                            const CubicSplineKernel& kernel, const Real* mass, Real* rho,
                            std::size_t count)
{
    const Real radius = kernel.supportRadius();
    parallel::forEach(0, count, [&](std::size_t i) {
        Real sum = 0;
        grid.forEachInRadius(x[i], radius,
                             [&](Index j, const Vec3&, Real r) { sum += mass[j] * kernel.W(r); });
        rho[i] = sum;
    });
}

/// Full-precision text of a value for error messages.
std::string exact(double value)
{
    char text[32];
    std::snprintf(text, sizeof(text), "%.9g", value);
    return text;
}

void requireAgreement(const std::vector<Real>& reference, const std::vector<Real>& rho,
                      const std::string& what)
{
    for (std::size_t i = 0; i < reference.size(); ++i) {
        const double a = reference[i], b = rho[i];
        const double rel = std::abs(a - b) / std::max(std::abs(a), 1e-30);
        if (!(rel <= DENSITY_REL_TOL)) {
            throw std::runtime_error(
                ghostfx::msg("density check failed for ", reference.size(), " particles: ", what,
                             " gives rho[", i, "] = ", exact(b), " kg/m^3, NeighborGrid gives ",
                             exact(a), " (relative difference ", rel, " > ", DENSITY_REL_TOL, ")"));
        }
    }
}

double maxRelativeDifference(const std::vector<Real>& a, const std::vector<Real>& b)
{
    double worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        worst = std::max(worst, std::abs(double(a[i]) - double(b[i])) / std::abs(double(a[i])));
    }
    return worst;
}

/// Build the scenario once per size and order and check, outside any timing, that every search
/// and path benchmarked with it computes the same densities.
const Scenario& scenario(std::size_t count, Order order)
{
    static std::map<std::pair<std::size_t, Order>, std::unique_ptr<Scenario>> cache;
    auto found = cache.find({count, order});
    if (found != cache.end()) return *found->second;

    auto sc = std::make_unique<Scenario>(count, order);
    sc->x = jitteredLattice(count, order);
    const Real m = Real(REST_DENSITY * SPACING * SPACING * SPACING);
    sc->mass.assign(count, m);
    sc->particles.addBatch(sc->x, m, ParticleKind::Liquid);
    const Real radius = sc->kernel.supportRadius();

    // Reference: NeighborGrid, particles in the scenario's order.
    NeighborGrid grid(radius);
    grid.build(sc->x);
    std::vector<Real> reference(count);
    ghostfxDensity(grid, sc->kernel, sc->mass.data(), reference.data(), count);
    const double pairs = parallel::sum(0, count, [&](std::size_t i) {
        std::size_t n = 0;
        grid.forEachNeighbor(Index(i), [&](Index, const Vec3&, Real) { ++n; });
        return double(n);
    });
    sc->neighboursPerParticle = pairs / double(count);

    // Every PointIndexGrid configuration the benchmarks use with this order (the variants run
    // in lattice order only).
    double worst = 0;
    std::vector<Real> rho(count);
    const std::vector<int> voxelsPerRadiusUsed = order == Order::Lattice
                                                     ? std::vector<int>{1, 2, 3}
                                                     : std::vector<int>{PIG_VOXELS_PER_RADIUS};
    for (int voxelsPerRadius : voxelsPerRadiusUsed) {
        PointIndexDensity pig(double(radius) / voxelsPerRadius);
        pig.build(sc->x.data(), count);
        const double pigPairs = double(pig.countPairs(radius));
        if (pigPairs != pairs) {
            throw std::runtime_error(ghostfx::msg(
                "pair count check failed for ", count, " particles: PointIndexGrid (voxel R/",
                voxelsPerRadius, ") finds ", pigPairs, " pairs within R, NeighborGrid ", pairs));
        }
        for (PointIndexQuery query :
             {PointIndexQuery::BoxThenDistance, PointIndexQuery::RadialSubvoxel}) {
            if (order != Order::Lattice && query != PIG_QUERY) continue;
            std::fill(rho.begin(), rho.end(), Real(0));
            pig.density(sc->kernel, sc->mass.data(), rho.data(), query);
            requireAgreement(reference, rho,
                             ghostfx::msg("PointIndexGrid (voxel R/", voxelsPerRadius, ", ",
                                          ghostfx::bench::queryName(query), ")"));
            worst = std::max(worst, maxRelativeDifference(reference, rho));
        }
    }

    // NeighborGrid with cells of R/2 (BM_GhostfxGrid_DensityVariant, lattice order only).
    if (order == Order::Lattice) {
        NeighborGrid halfCells(radius / Real(2));
        halfCells.build(sc->x);
        ghostfxDensityInRadius(halfCells, sc->x.data(), sc->kernel, sc->mass.data(), rho.data(),
                               count);
        requireAgreement(reference, rho, "NeighborGrid with cells of R/2");
        worst = std::max(worst, maxRelativeDifference(reference, rho));
    }

    // The sorted path of BM_GhostfxGrid_BuildSortDensity, mapped back through the ids
    // (addBatch gave particle i the id i).
    ParticleSet sorted = sc->particles;
    grid.sortParticles(sorted);
    ghostfxDensity(grid, sc->kernel, sorted.masses().data(), sorted.densities().data(), count);
    for (std::size_t k = 0; k < count; ++k) {
        rho[std::size_t(sorted.ids()[k])] = sorted.densities()[k];
    }
    requireAgreement(reference, rho, "NeighborGrid after sortParticles");
    worst = std::max(worst, maxRelativeDifference(reference, rho));

    const auto [lo, hi] = std::minmax_element(reference.begin(), reference.end());
    std::fprintf(stderr,
                 "scenario N = %zu, %s order: %.2f neighbours per particle, rho in [%.1f, %.1f] "
                 "kg/m^3; all searches agree, max relative difference %.2e (limit %.0e)\n",
                 count, orderName(order), sc->neighboursPerParticle, double(*lo), double(*hi),
                 worst, DENSITY_REL_TOL);
    return *cache.emplace(std::make_pair(count, order), std::move(sc)).first->second;
}

void setCounters(benchmark::State& state, const Scenario& sc, std::size_t memoryBytes = 0)
{
    state.counters["particles"] = double(sc.count);
    state.counters["nbrs/particle"] = sc.neighboursPerParticle;
    if (memoryBytes > 0) state.counters["mem_MB"] = double(memoryBytes) / 1e6;
}

/// Time `pass` (a density pass writing `rho`) once per iteration, its output kept from the
/// optimiser.
template <typename Pass>
void timePasses(benchmark::State& state, const Real* rho, Pass&& pass)
{
    for (auto _ : state) {
        pass();
        benchmark::DoNotOptimize(rho);
        benchmark::ClobberMemory();
    }
}

// ---------------------------------------------------------------------------------------------
// ghostfx NeighborGrid
// ---------------------------------------------------------------------------------------------

/// Build only. The grid object persists across iterations, as in a solver.
void BM_GhostfxGrid_Build(benchmark::State& state, Order order)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    NeighborGrid grid(sc.kernel.supportRadius());
    for (auto _ : state) {
        grid.build(sc.x);
        benchmark::ClobberMemory();
    }
    setCounters(state, sc, grid.memoryBytes());
}

/// One density pass over the particles in the scenario's order, grid already built.
void BM_GhostfxGrid_Density(benchmark::State& state, Order order)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    NeighborGrid grid(sc.kernel.supportRadius());
    grid.build(sc.x);
    std::vector<Real> rho(sc.count);
    timePasses(state, rho.data(),
               [&] { ghostfxDensity(grid, sc.kernel, sc.mass.data(), rho.data(), sc.count); });
    setCounters(state, sc);
}

/// One density pass over a ParticleSet already sorted by NeighborGrid::sortParticles.
void BM_GhostfxGrid_DensitySorted(benchmark::State& state, Order order)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    NeighborGrid grid(sc.kernel.supportRadius());
    ParticleSet particles = sc.particles;
    grid.sortParticles(particles);
    timePasses(state, particles.densities().data(), [&] {
        ghostfxDensity(grid, sc.kernel, particles.masses().data(), particles.densities().data(),
                       sc.count);
    });
    setCounters(state, sc);
}

/// Build + density without reordering: the direct counterpart of BM_PointIndexGrid_BuildDensity.
void BM_GhostfxGrid_BuildDensity(benchmark::State& state, Order order)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    NeighborGrid grid(sc.kernel.supportRadius());
    std::vector<Real> rho(sc.count);
    timePasses(state, rho.data(), [&] {
        grid.build(sc.x);
        ghostfxDensity(grid, sc.kernel, sc.mass.data(), rho.data(), sc.count);
    });
    setCounters(state, sc);
}

/// The per-step cost in a solver: build, reorder every channel of the ParticleSet by cell
/// (NeighborGrid::sortParticles), then the density pass on the sorted set. Each iteration starts
/// from the scenario's order again (restored outside the timing), so the reorder moves every
/// particle: an upper bound on a solver step, whose particles are still nearly sorted.
void BM_GhostfxGrid_BuildSortDensity(benchmark::State& state, Order order)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    NeighborGrid grid(sc.kernel.supportRadius());
    ParticleSet particles;
    for (auto _ : state) {
        state.PauseTiming();
        particles = sc.particles;
        state.ResumeTiming();
        grid.sortParticles(particles);
        ghostfxDensity(grid, sc.kernel, particles.masses().data(), particles.densities().data(),
                       sc.count);
        benchmark::DoNotOptimize(particles.densities().data());
        benchmark::ClobberMemory();
    }
    setCounters(state, sc);
}

/// Density with cells of side R / cellsPerR, querying radius R (forEachInRadius), lattice order.
/// Args {N, cells per R}: the same tuning knob as the PointIndexGrid voxel size.
void BM_GhostfxGrid_DensityVariant(benchmark::State& state)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), Order::Lattice);
    const int cellsPerRadius = int(state.range(1));
    NeighborGrid grid(sc.kernel.supportRadius() / Real(cellsPerRadius));
    grid.build(sc.x);
    std::vector<Real> rho(sc.count);
    timePasses(state, rho.data(), [&] {
        ghostfxDensityInRadius(grid, sc.x.data(), sc.kernel, sc.mass.data(), rho.data(), sc.count);
    });
    setCounters(state, sc, grid.memoryBytes());
    state.SetLabel(ghostfx::msg("cell R/", cellsPerRadius));
}

// ---------------------------------------------------------------------------------------------
// OpenVDB tools::PointIndexGrid
// ---------------------------------------------------------------------------------------------

double pigVoxelSize(const Scenario& sc, int voxelsPerRadius)
{
    return double(sc.kernel.supportRadius()) / voxelsPerRadius;
}

std::string pigLabel(int voxelsPerRadius, PointIndexQuery query)
{
    return ghostfx::msg("voxel R/", voxelsPerRadius, ", ", ghostfx::bench::queryName(query));
}

/// tools::createPointIndexGrid (a new grid per call: that is the API).
void pigBuild(benchmark::State& state, Order order, int voxelsPerRadius)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    PointIndexDensity pig(pigVoxelSize(sc, voxelsPerRadius));
    for (auto _ : state) {
        pig.build(sc.x.data(), sc.count);
        benchmark::ClobberMemory();
    }
    setCounters(state, sc, pig.memoryBytes());
    state.SetLabel(ghostfx::msg("voxel R/", voxelsPerRadius));
}

/// One density pass, index grid already built.
void pigDensity(benchmark::State& state, Order order, int voxelsPerRadius, PointIndexQuery query)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    PointIndexDensity pig(pigVoxelSize(sc, voxelsPerRadius));
    pig.build(sc.x.data(), sc.count);
    std::vector<Real> rho(sc.count);
    timePasses(state, rho.data(),
               [&] { pig.density(sc.kernel, sc.mass.data(), rho.data(), query); });
    setCounters(state, sc);
    state.SetLabel(pigLabel(voxelsPerRadius, query));
}

void BM_PointIndexGrid_Build(benchmark::State& state, Order order)
{
    pigBuild(state, order, PIG_VOXELS_PER_RADIUS);
}

void BM_PointIndexGrid_Density(benchmark::State& state, Order order)
{
    pigDensity(state, order, PIG_VOXELS_PER_RADIUS, PIG_QUERY);
}

void BM_PointIndexGrid_BuildDensity(benchmark::State& state, Order order)
{
    const Scenario& sc = scenario(std::size_t(state.range(0)), order);
    PointIndexDensity pig(pigVoxelSize(sc, PIG_VOXELS_PER_RADIUS));
    std::vector<Real> rho(sc.count);
    timePasses(state, rho.data(), [&] {
        pig.build(sc.x.data(), sc.count);
        pig.density(sc.kernel, sc.mass.data(), rho.data(), PIG_QUERY);
    });
    setCounters(state, sc);
    state.SetLabel(pigLabel(PIG_VOXELS_PER_RADIUS, PIG_QUERY));
}

/// Args {N, voxels per R}.
void BM_PointIndexGrid_BuildVariant(benchmark::State& state)
{
    pigBuild(state, Order::Lattice, int(state.range(1)));
}

/// Args {N, voxels per R, query}.
void BM_PointIndexGrid_DensityVariant(benchmark::State& state)
{
    pigDensity(state, Order::Lattice, int(state.range(1)), PointIndexQuery(state.range(2)));
}

void sizes(benchmark::internal::Benchmark* b)
{
    b->Arg(100000)->Arg(1000000)->UseRealTime()->MeasureProcessCPUTime()->Unit(
        benchmark::kMillisecond);
}

/// Variants: {N, voxels per R, query}, to choose the fairest PointIndexGrid configuration.
void pigBuildVariants(benchmark::internal::Benchmark* b)
{
    for (long n : {100000L, 1000000L}) {
        for (long vpr : {1L, 2L, 3L}) b->Args({n, vpr});
    }
    b->ArgNames({"N", "voxelsPerR"})
        ->UseRealTime()
        ->MeasureProcessCPUTime()
        ->Unit(benchmark::kMillisecond);
}

void pigDensityVariants(benchmark::internal::Benchmark* b)
{
    for (long n : {100000L, 1000000L}) {
        for (long vpr : {1L, 2L, 3L}) {
            for (long q :
                 {long(PointIndexQuery::BoxThenDistance), long(PointIndexQuery::RadialSubvoxel)}) {
                b->Args({n, vpr, q});
            }
        }
    }
    b->ArgNames({"N", "voxelsPerR", "query"})
        ->UseRealTime()
        ->MeasureProcessCPUTime()
        ->Unit(benchmark::kMillisecond);
}

} // namespace

BENCHMARK_CAPTURE(BM_GhostfxGrid_Build, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_Density, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_DensitySorted, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_BuildDensity, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_BuildSortDensity, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_PointIndexGrid_Build, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_PointIndexGrid_Density, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_PointIndexGrid_BuildDensity, lattice, Order::Lattice)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_Build, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_Density, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_DensitySorted, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_BuildDensity, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK_CAPTURE(BM_GhostfxGrid_BuildSortDensity, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK_CAPTURE(BM_PointIndexGrid_Build, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK_CAPTURE(BM_PointIndexGrid_Density, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK_CAPTURE(BM_PointIndexGrid_BuildDensity, shuffled, Order::Shuffled)->Apply(sizes);
BENCHMARK(BM_GhostfxGrid_DensityVariant)
    ->ArgsProduct({{100000, 1000000}, {1, 2}})
    ->ArgNames({"N", "cellsPerR"})
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointIndexGrid_BuildVariant)->Apply(pigBuildVariants);
BENCHMARK(BM_PointIndexGrid_DensityVariant)->Apply(pigDensityVariants);

int main(int argc, char** argv)
{
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::AddCustomContext("ghostfx_build_type", GHOSTFX_BUILD_TYPE);
    benchmark::AddCustomContext("ghostfx_real", sizeof(Real) == 4 ? "float" : "double");
    benchmark::AddCustomContext("tbb_threads", std::to_string(parallel::maxThreads()));
    try {
        benchmark::RunSpecifiedBenchmarks();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_neighbors: %s\n", e.what());
        return 1;
    }
    benchmark::Shutdown();
    return 0;
}
