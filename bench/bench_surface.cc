/// @file   bench_surface.cc
/// @brief  Cost of the liquid surface level set, union of spheres against anisotropic kernels
///         (Yu and Turk 2013), on the same particles (vdbio/FrameFiles.h, makeVolumeGrids with
///         only the surface asked for).
/// @details Scenario: bench_frame_write.cc's liquid cube (LiquidCube.h), at rest: a jittered
///          cubic lattice, spacing h = 0.01 m, jitter uniform in +-0.1 h per axis from a fixed
///          seed, the last layer partial so the count is exact; mass rho0 h^3,
///          rho0 = 1000 kg/m^3. Voxel h / 2, every other setting the
///          VolumeOptions default. Times building the "surface" grid only (no file), one
///          iteration per run, wall time (the work is multi-threaded); `process_cpu_s` is the
///          CPU time of all threads of the process during the timed iteration (getrusage): on a
///          machine shared with other jobs wall time alone says little. Results and how they
///          were taken: bench/RESULTS.md, "Anisotropic surface (Yu and Turk)".
#include "BenchCommon.h"
#include "LiquidCube.h"

#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <benchmark/benchmark.h>

using namespace ghostfx;
using bench::processCpuSeconds;

namespace {

void surface(benchmark::State& state, vdbio::SurfaceMethod method)
{
    const sph::ParticleSet& p =
        bench::liquidCube(std::size_t(state.range(0)), bench::CubeVelocity::Rest);
    vdbio::VolumeOptions o = bench::cubeVolumeOptions();
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
