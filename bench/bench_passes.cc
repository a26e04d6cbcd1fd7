/// @file   bench_passes.cc
/// @brief  The pieces of a liquid step at 1e5 particles: the grid build and sort, the one
///         neighbour search into compact lists (sph::NeighborLists), and SPH pair sums over the
///         lists written pair by pair and in SIMD batches (sph::PairBatch).
/// @details Scenario: 1e5 particles on a jittered cubic lattice (spacing h = 0.01 m, jitter
///          +-0.1 h), sorted by the grid as a solver sorts them each step; kernel support 3 h
///          ([SB12] Sec. 3), about 110 neighbours per particle. Passes:
///            - density: rho_i = sum_j m_j W(r_ij);
///            - pressure: a_i = -sum_j m_j (p_i / rho_i^2 + p_j / rho_j^2) grad W_ij;
///          each as a plain per-pair loop (`Scalar`) and batched (`Batch`). Before timing, the
///          two forms are checked to agree per particle to 1e-4 relative (main exits 1 if not).
///          Results and conclusions: bench/RESULTS.md, "Liquid step".
#include "ghostfx/sph/Kernels.h"
#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/NeighborLists.h"
#include "ghostfx/sph/PairBatch.h"
#include "ghostfx/sph/Parallel.h"
#include "ghostfx/sph/ParticleSet.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

using namespace ghostfx::sph;
namespace parallel = ghostfx::parallel;

constexpr double SPACING = 0.01;
constexpr std::size_t COUNT = 100000;

struct Scene
{
    Scene() : kernel(Real(3 * SPACING)), grid(Real(3 * SPACING))
    {
        std::mt19937 rng(11);
        std::uniform_real_distribution<double> jitter(-0.1, 0.1);
        const std::size_t side = std::size_t(std::ceil(std::cbrt(double(COUNT))));
        std::vector<Vec3> x;
        for (std::size_t i = 0; i < side && x.size() < COUNT; ++i)
            for (std::size_t j = 0; j < side && x.size() < COUNT; ++j)
                for (std::size_t k = 0; k < side && x.size() < COUNT; ++k)
                    x.emplace_back(Real((i + 0.5 + jitter(rng)) * SPACING),
                                   Real((j + 0.5 + jitter(rng)) * SPACING),
                                   Real((k + 0.5 + jitter(rng)) * SPACING));
        std::shuffle(x.begin(), x.end(), std::mt19937(5));
        const Real m = Real(1000 * SPACING * SPACING * SPACING);
        particles.addBatch(x, m, ParticleKind::Liquid);
        grid.sortParticles(particles);
        lists.build(grid, particles.positions().data(), COUNT, kernel.supportRadius());
        rho.assign(COUNT, 0);
        p.assign(COUNT, 0);
        for (std::size_t i = 0; i < COUNT; ++i) {
            // Some pressure field that varies from particle to particle.
            p[i] = Real(100 + 10 * std::sin(double(i)));
            rho[i] = Real(1000 + std::cos(double(i)));
        }
        ratio.resize(COUNT);
        for (std::size_t i = 0; i < COUNT; ++i) ratio[i] = p[i] / (rho[i] * rho[i]);
    }

    CubicSplineKernel kernel;
    NeighborGrid grid;
    ParticleSet particles;
    NeighborLists lists;
    std::vector<Real> rho, p, ratio;
};

Scene& scene()
{
    static Scene s;
    return s;
}

/// The grain of every pass: particles per task.
constexpr std::size_t GRAIN = 512;

/// A pair-by-pair pass: `perParticle(i)` for every particle, in parallel.
template <typename PerParticle>
void eachParticle(PerParticle&& perParticle)
{
    parallel::forEach(0, COUNT, perParticle, GRAIN);
}

/// A batched pass: `perBlock(b, lo, hi)` for each block [lo, hi) of particles, in parallel,
/// with one PairBatch `b` per block.
template <typename PerBlock>
void eachBlock(PerBlock&& perBlock)
{
    parallel::forRange(
        0, COUNT,
        [&](std::size_t lo, std::size_t hi) {
        PairBatch b;
        perBlock(b, lo, hi);
        },
        GRAIN);
}

void densityScalar(const Scene& s, std::vector<Real>& out)
{
    const auto& x = s.particles.positions();
    const auto& m = s.particles.masses();
    eachParticle([&](std::size_t i) {
        Real sum = 0;
        s.lists[i].forEach([&](Index j) { sum += m[j] * s.kernel.W((x[i] - x[j]).length()); });
        out[i] = sum;
    });
}

void densityBatch(const Scene& s, std::vector<Real>& out)
{
    const auto& x = s.particles.positions();
    const auto& m = s.particles.masses();
    eachBlock([&](PairBatch& b, std::size_t lo, std::size_t hi) {
        const CubicSplineKernel kernel = s.kernel;
        for (std::size_t i = lo; i < hi; ++i) {
            Real sum = 0;
            b.forEachBatch(x[i], x.data(), s.lists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]];
                for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]);
                sum += b.sum(b.f);
            });
            out[i] = sum;
        }
    });
}

void pressureScalar(const Scene& s, std::vector<Vec3>& out)
{
    const auto& x = s.particles.positions();
    const auto& m = s.particles.masses();
    eachParticle([&](std::size_t i) {
        Vec3 a(0);
        const Real pi = s.ratio[i];
        s.lists[i].forEach([&](Index j) {
            if (j == i) return;
            const Vec3 xij = x[i] - x[j];
            a -= m[j] * (pi + s.ratio[j]) * s.kernel.gradW(xij, xij.length());
        });
        out[i] = a;
    });
}

void pressureBatch(const Scene& s, std::vector<Vec3>& out)
{
    const auto& x = s.particles.positions();
    const auto& m = s.particles.masses();
    eachBlock([&](PairBatch& b, std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) {
            const Real pi = s.ratio[i];
            Vec3 a(0);
            b.forEachBatch(x[i], x.data(), s.lists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]] * (pi + s.ratio[b.j[k]]);
                for (int k = 0; k < b.n; ++k) b.f[k] *= -s.kernel.gradFactor(b.r[k]);
                a += b.sumScaledOffsets(b.f);
            });
            out[i] = a;
        }
    });
}

/// Google Benchmark's counter of nanoseconds per pair, for `pairs` pairs an iteration.
benchmark::Counter nsPerPair(std::size_t pairs)
{
    return benchmark::Counter(double(pairs) * 1e-9, benchmark::Counter::kIsIterationInvariantRate
                                                        | benchmark::Counter::kInvert);
}

void BM_GridSort(benchmark::State& state)
{
    Scene& s = scene();
    ParticleSet copy = s.particles;
    NeighborGrid grid(s.kernel.supportRadius());
    for (auto _ : state) grid.sortParticles(copy);
    state.counters["particles/s"] =
        benchmark::Counter(double(COUNT), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_ListsBuild(benchmark::State& state)
{
    Scene& s = scene();
    NeighborLists lists;
    for (auto _ : state)
        lists.build(s.grid, s.particles.positions().data(), COUNT, s.kernel.supportRadius());
    state.counters["pairs"] = double(lists.pairCount());
    state.counters["ns/pair"] = nsPerPair(lists.pairCount());
}

/// One pass (a density or a pressure force, `T` per particle) over the scene's lists.
template <typename T, void (*Pass)(const Scene&, std::vector<T>&)>
void BM_Pass(benchmark::State& state)
{
    Scene& s = scene();
    std::vector<T> out(COUNT);
    for (auto _ : state) Pass(s, out);
    state.counters["ns/pair"] = nsPerPair(s.lists.pairCount());
}

BENCHMARK(BM_GridSort)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ListsBuild)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Pass<Real, densityScalar>)->Name("BM_Density/Scalar")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Pass<Real, densityBatch>)->Name("BM_Density/Batch")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Pass<Vec3, pressureScalar>)->Name("BM_Pressure/Scalar")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Pass<Vec3, pressureBatch>)->Name("BM_Pressure/Batch")->Unit(benchmark::kMillisecond);

/// Outside any timing: the batched passes give what the plain ones give.
void checkAgreement()
{
    const Scene& s = scene();
    std::vector<Real> a(COUNT), b(COUNT);
    densityScalar(s, a);
    densityBatch(s, b);
    std::vector<Vec3> pa(COUNT), pb(COUNT);
    pressureScalar(s, pa);
    pressureBatch(s, pb);
    double scale = 0;
    for (const Vec3& v : pa) scale = std::max(scale, double(v.length()));
    for (std::size_t i = 0; i < COUNT; ++i) {
        if (std::abs(a[i] - b[i]) > 1e-4 * std::abs(a[i])
            || (pa[i] - pb[i]).length() > 1e-4 * scale) {
            throw std::runtime_error(
                ghostfx::msg("batched pass disagrees at particle ", i, ": density ", a[i], " vs ",
                             b[i], ", pressure force |diff| ", (pa[i] - pb[i]).length()));
        }
    }
}

} // namespace

int main(int argc, char** argv)
{
    try {
        checkAgreement();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_passes: %s\n", e.what());
        return 1;
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
