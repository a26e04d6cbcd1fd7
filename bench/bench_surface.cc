/// @file   bench_surface.cc
/// @brief  Cost of the liquid surface level set, union of spheres against anisotropic kernels
///         (Yu and Turk 2013), on the same particles (vdbio/FrameFiles.h, makeVolumeGrids with
///         only the surface asked for).
/// @details Scenario: bench_frame_write.cc's liquid cube (copied here so each benchmark program
///          stands alone): a jittered cubic lattice, spacing h = 0.01 m, jitter uniform in
///          +-0.1 h per axis from a fixed seed, the last layer partial so the count is exact;
///          mass rho0 h^3, rho0 = 1000 kg/m^3. Voxel h / 2, every other setting the
///          VolumeOptions default. Times building the "surface" grid only (no file), one
///          iteration per run, wall time (the work is multi-threaded); `process_cpu_s` is the
///          CPU time of all threads of the process during the timed iteration (getrusage): on a
///          machine shared with other jobs wall time alone says little. Results and how they
///          were taken: bench/RESULTS.md, "Anisotropic surface (Yu and Turk)".
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/Random.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>

#include <sys/resource.h>

using namespace ghostfx;

namespace {

constexpr double SPACING = 0.01;      // h (m)
constexpr double REST_DENSITY = 1000; // rho0 (kg/m^3)

/// Jittered lattice cube of exactly `count` liquid particles (cached per count).
const sph::ParticleSet& liquidCube(std::size_t count)
{
    static std::map<std::size_t, std::unique_ptr<sph::ParticleSet>> cache;
    auto& slot = cache[count];
    if (slot) return *slot;
    slot = std::make_unique<sph::ParticleSet>();
    sph::ParticleSet& p = *slot;
    const int side = int(std::ceil(std::cbrt(double(count))));
    sph::Rng rng(20240611);
    const sph::Real h = sph::Real(SPACING);
    const sph::Real m = sph::Real(REST_DENSITY * SPACING * SPACING * SPACING);
    p.reserve(count);
    for (int i = 0; i < side && p.size() < count; ++i) {
        for (int j = 0; j < side && p.size() < count; ++j) {
            for (int k = 0; k < side && p.size() < count; ++k) {
                const sph::Vec3 x(h * (sph::Real(i) + rng.uniform(-0.1f, 0.1f)),
                                  h * (sph::Real(j) + rng.uniform(-0.1f, 0.1f)),
                                  h * (sph::Real(k) + rng.uniform(-0.1f, 0.1f)));
                p.add(x, sph::Vec3(0), m, sph::ParticleKind::Liquid);
            }
        }
    }
    for (auto& rho : p.densities()) rho = sph::Real(REST_DENSITY);
    return p;
}

/// User + system CPU time of every thread of this process so far (s).
double processCpuSeconds()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec)
           + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void surface(benchmark::State& state, vdbio::SurfaceMethod method)
{
    const sph::ParticleSet& p = liquidCube(std::size_t(state.range(0)));
    vdbio::VolumeOptions o;
    o.voxelSize = 0.5 * SPACING;
    o.kernelSupport = 3 * SPACING;
    o.restDensity = REST_DENSITY;
    o.particleSpacing = SPACING;
    o.density = o.velocity = false;
    o.surfaceMethod = method;
    double voxels = 0;
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) {
        const openvdb::GridPtrVec grids = vdbio::makeVolumeGrids(p, o);
        voxels = double(grids.at(0)->activeVoxelCount());
    }
    state.counters["process_cpu_s"] = processCpuSeconds() - cpu0;
    state.counters["particles"] = double(p.size());
    state.counters["active_voxels"] = voxels;
}

void BM_SurfaceSpheres(benchmark::State& state) { surface(state, vdbio::SurfaceMethod::Spheres); }
void BM_SurfaceAnisotropic(benchmark::State& state)
{
    surface(state, vdbio::SurfaceMethod::Anisotropic);
}

void sizes(benchmark::internal::Benchmark* b)
{
    b->Arg(100000)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
}

struct InitOpenVdb
{
    InitOpenVdb() { openvdb::initialize(); }
} initOpenVdb;

} // namespace

BENCHMARK(BM_SurfaceSpheres)->Apply(sizes);
BENCHMARK(BM_SurfaceAnisotropic)->Apply(sizes);
