/// @file   bench_sampler.cc
/// @brief  Poisson-disk sampling rate ([SB12] Sec. 4.5): particles per second for the full
///         volume pipeline (surface sampling, surface relaxation, interior sampling, volume
///         relaxation) of a sphere holding about 1e5 particles, and each phase on its own.
/// @details Run: build/bench/bench_sampler --benchmark_counters_tabular=true
///          Arg = number of threads (relaxation runs in parallel by block colouring; the
///          sampling phases are sequential by nature).
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/PoissonSampler.h>

#include <benchmark/benchmark.h>

#include <cmath>

using namespace ghostfx;
using namespace ghostfx::sph;

namespace {

constexpr Real SPACING = Real(0.01); // h (m)
// Our sampler packs about 0.75 samples per h^3 after relaxation (tests/sph/test_sampler.cc),
// so a sphere of radius 31.7 h holds about 1e5 particles.
constexpr Real SPHERE_RADIUS = Real(31.7) * SPACING;

const LevelSet& sphere()
{
    static const LevelSet ls = [] {
        openvdb::initialize();
        return makeLevelSet(makeSphereLevelSet(Vec3(0), SPHERE_RADIUS, Real(0.5) * SPACING),
                            "sphere");
    }();
    return ls;
}

/// 48 bits of an FNV-1a hash of the sample coordinates' bytes: equal across builds exactly when
/// the samples are (a change meant to be a pure speed-up must keep it).
double checksum(const SampleSet& s)
{
    std::uint64_t h = 1469598103934665603ULL;
    const auto* bytes = reinterpret_cast<const unsigned char*>(s.positions.data());
    for (std::size_t k = 0; k < s.positions.size() * sizeof(Vec3); ++k) {
        h = (h ^ bytes[k]) * 1099511628211ULL;
    }
    return double(h >> 16);
}

void reportRate(benchmark::State& state, std::size_t particles)
{
    state.counters["particles"] = double(particles);
    state.counters["particles/s"] = benchmark::Counter(
        double(particles) * double(state.iterations()), benchmark::Counter::kIsRate);
}

/// The full pipeline (sampleVolume) with `settings`, its rate and the samples' checksum.
void samplePipeline(benchmark::State& state, const PoissonSettings& settings)
{
    parallel::ThreadLimit limit(int(state.range(0)));
    const PoissonDiskSampler sampler(settings);
    std::size_t n = 0;
    double hash = 0;
    for (auto _ : state) {
        const SampleSet s = sampler.sampleVolume(sphere());
        n = s.size();
        hash = checksum(s);
        benchmark::DoNotOptimize(s.positions.data());
    }
    reportRate(state, n);
    state.counters["checksum"] = hash;
}

void BM_SampleVolume(benchmark::State& state)
{
    samplePipeline(state, PoissonSettings::forSpacing(SPACING));
}

/// A ghost-solid band: the same sphere sampled one kernel radius (3h) deep, as a solid's
/// ghost particles are ([SB12] Sec. 4.5.2). Nearly every sample is within a few r of the
/// surface, so level-set lookups and projections weigh more than in the full volume.
void BM_SampleSolidBand(benchmark::State& state)
{
    PoissonSettings settings = PoissonSettings::forSpacing(SPACING);
    settings.bandDepth = Real(3) * SPACING;
    samplePipeline(state, settings);
}

/// The same pipeline with the interior deeper than 2r from a relaxed periodic tile
/// (PoissonSettings::tiledInterior, scene key settings.tiled_sampling).
void BM_SampleVolumeTiled(benchmark::State& state)
{
    PoissonSettings settings = PoissonSettings::forSpacing(SPACING);
    settings.tiledInterior = true;
    samplePipeline(state, settings);
}

/// The full pipeline and the solid band with SPH packing as the volume relaxation
/// (PoissonSettings::Relaxation::Packing, scene key settings.sampling_relaxation).
void BM_SampleVolumePacking(benchmark::State& state)
{
    PoissonSettings settings = PoissonSettings::forSpacing(SPACING);
    settings.volumeRelaxation = PoissonSettings::Relaxation::Packing;
    samplePipeline(state, settings);
}

void BM_SampleSolidBandPacking(benchmark::State& state)
{
    PoissonSettings settings = PoissonSettings::forSpacing(SPACING);
    settings.bandDepth = Real(3) * SPACING;
    settings.volumeRelaxation = PoissonSettings::Relaxation::Packing;
    samplePipeline(state, settings);
}

void BM_SampleWithoutRelaxation(benchmark::State& state)
{
    parallel::ThreadLimit limit(int(state.range(0)));
    const PoissonDiskSampler sampler(PoissonSettings::forSpacing(SPACING));
    std::size_t n = 0;
    for (auto _ : state) {
        SampleSet s = sampler.sampleSurface(sphere());
        sampler.sampleInterior(s, sphere());
        n = s.size();
        benchmark::DoNotOptimize(s.positions.data());
    }
    reportRate(state, n);
}

void BM_VolumeRelaxationSweep(benchmark::State& state)
{
    parallel::ThreadLimit limit(int(state.range(0)));
    const PoissonDiskSampler sampler(PoissonSettings::forSpacing(SPACING));
    SampleSet s = sampler.sampleSurface(sphere());
    sampler.sampleInterior(s, sphere());
    int pass = 0;
    for (auto _ : state) {
        sampler.relax(s, sphere(), 1, ++pass);
        benchmark::DoNotOptimize(s.positions.data());
    }
    reportRate(state, s.size());
}

} // namespace

BENCHMARK(BM_SampleVolume)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_SampleSolidBand)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_SampleVolumePacking)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_SampleSolidBandPacking)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_SampleVolumeTiled)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_SampleWithoutRelaxation)
    ->Arg(1)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_VolumeRelaxationSweep)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

BENCHMARK_MAIN();
