/// @file   bench_frame_write.cc
/// @brief  Cost of writing one output frame (vdbio/FrameFiles.h): points file, surface level
///         set, density fog, separately and together, at 1e5 and 1e6 liquid particles.
/// @details Scenario: a cube of liquid particles on a jittered cubic lattice, spacing
///          h = 0.01 m, jitter uniform in +-0.1 h per axis from a fixed seed, the last layer
///          partial so the count is exact; mass rho0 h^3 with rho0 = 1000 kg/m^3; velocity a
///          smooth swirl. Grids: voxel h / 2, kernel support R = 3 h ([SB12] Sec. 3), surface
///          with the VolumeOptions defaults. Each benchmark times building the grids and writing
///          the file into a temporary folder (atomic write included), one iteration, wall time
///          (the work is multi-threaded). Counters: file size (MB), active voxels, and
///          `process_cpu_s`, the CPU time of all threads of the process (getrusage) during the
///          timed iteration: on a machine shared with other jobs, wall time alone says little.
///          Results and how they were taken: bench/RESULTS.md, "Frame output".
#include "BenchCommon.h"
#include "LiquidCube.h"

#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using namespace ghostfx;
using bench::processCpuSeconds;

namespace {

/// The cube with the swirl, so the vel grid has something to hold.
const sph::ParticleSet& liquidCube(std::size_t count)
{
    return bench::liquidCube(count, bench::CubeVelocity::Swirl);
}

vdbio::VolumeOptions volumeOptions(bool surface, bool density, bool velocity)
{
    vdbio::VolumeOptions o = bench::cubeVolumeOptions();
    o.surface = surface;
    o.density = density;
    o.velocity = velocity;
    return o;
}

fs::path outputDir()
{
    const fs::path dir = fs::temp_directory_path() / "ghostfx_bench_frame_write";
    fs::create_directories(dir);
    return dir;
}

double megabytes(const fs::path& path) { return double(fs::file_size(path)) / 1e6; }

void writeVolume(benchmark::State& state, bool surface, bool density, bool velocity)
{
    const sph::ParticleSet& p = liquidCube(std::size_t(state.range(0)));
    const fs::path path = outputDir() / "volume.vdb";
    double voxels = 0;
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) {
        const openvdb::GridPtrVec grids =
            vdbio::makeVolumeGrids(p, volumeOptions(surface, density, velocity));
        vdbio::writeVolumeFile(path.string(), grids);
        voxels = 0;
        for (const auto& g : grids) voxels += double(g->activeVoxelCount());
    }
    state.counters["process_cpu_s"] = processCpuSeconds() - cpu0;
    state.counters["particles"] = double(p.size());
    state.counters["active_voxels"] = voxels;
    state.counters["file_MB"] = megabytes(path);
}

void BM_Points(benchmark::State& state)
{
    const sph::ParticleSet& p = liquidCube(std::size_t(state.range(0)));
    const fs::path path = outputDir() / "points.vdb";
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) vdbio::writePointsFile(path.string(), p, vdbio::PointsOptions());
    state.counters["process_cpu_s"] = processCpuSeconds() - cpu0;
    state.counters["particles"] = double(p.size());
    state.counters["file_MB"] = megabytes(path);
}

void BM_Surface(benchmark::State& state) { writeVolume(state, true, false, false); }
void BM_Density(benchmark::State& state) { writeVolume(state, false, true, false); }
void BM_DensityVel(benchmark::State& state) { writeVolume(state, false, true, true); }

/// A whole frame as the command line writes it: the points file and the volume file with
/// surface, density and vel.
void BM_Frame(benchmark::State& state)
{
    const sph::ParticleSet& p = liquidCube(std::size_t(state.range(0)));
    const fs::path points = outputDir() / "frame_points.vdb";
    const fs::path volume = outputDir() / "frame_volume.vdb";
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) {
        vdbio::writePointsFile(points.string(), p, vdbio::PointsOptions());
        vdbio::writeVolumeFile(volume.string(),
                               vdbio::makeVolumeGrids(p, volumeOptions(true, true, true)));
    }
    state.counters["process_cpu_s"] = processCpuSeconds() - cpu0;
    state.counters["particles"] = double(p.size());
    state.counters["file_MB"] = megabytes(points) + megabytes(volume);
}

void sizes(benchmark::internal::Benchmark* b)
{
    b->Arg(100000)->Arg(1000000)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
}

struct InitOpenVdb
{
    InitOpenVdb() { openvdb::initialize(); }
} initOpenVdb;

} // namespace

BENCHMARK(BM_Points)->Apply(sizes);
BENCHMARK(BM_Surface)->Apply(sizes);
BENCHMARK(BM_Density)->Apply(sizes);
BENCHMARK(BM_DensityVel)->Apply(sizes);
BENCHMARK(BM_Frame)->Apply(sizes);
