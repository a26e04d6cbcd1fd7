/// @file   LiquidCube.h
/// @brief  Benchmarks' scenario of the frame output and surface benchmarks (bench_frame_write,
///         bench_surface): a jittered lattice cube of liquid particles and the volume options
///         that grid it.
/// @details A cube of liquid particles on a jittered cubic lattice, spacing h = 0.01 m, jitter
///          uniform in +-0.1 h per axis from a fixed seed, the last layer partial so the count
///          is exact; mass rho0 h^3 with rho0 = 1000 kg/m^3, density rho0. Grids: voxel h / 2,
///          kernel support R = 3 h ([SB12] Sec. 3).
#pragma once

#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/Random.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <cmath>
#include <map>
#include <memory>
#include <utility>

namespace ghostfx {
namespace bench {

constexpr double CUBE_SPACING = 0.01;      ///< lattice spacing h (m)
constexpr double CUBE_REST_DENSITY = 1000; ///< rho0 (kg/m^3)

/// The particles' velocity: at rest, or a smooth swirl v = (-y, x, 0.1) m/s.
enum class CubeVelocity { Rest, Swirl };

/// Jittered lattice cube of exactly `count` liquid particles (cached per count and velocity).
inline const sph::ParticleSet& liquidCube(std::size_t count, CubeVelocity velocity)
{
    static std::map<std::pair<std::size_t, CubeVelocity>, std::unique_ptr<sph::ParticleSet>> cache;
    auto& slot = cache[{count, velocity}];
    if (slot) return *slot;
    slot = std::make_unique<sph::ParticleSet>();
    sph::ParticleSet& p = *slot;
    const int side = int(std::ceil(std::cbrt(double(count))));
    sph::Rng rng(20240611);
    const sph::Real h = sph::Real(CUBE_SPACING);
    const sph::Real m = sph::Real(CUBE_REST_DENSITY * CUBE_SPACING * CUBE_SPACING * CUBE_SPACING);
    p.reserve(count);
    for (int i = 0; i < side && p.size() < count; ++i) {
        for (int j = 0; j < side && p.size() < count; ++j) {
            for (int k = 0; k < side && p.size() < count; ++k) {
                const sph::Vec3 x(h * (sph::Real(i) + rng.uniform(-0.1f, 0.1f)),
                                  h * (sph::Real(j) + rng.uniform(-0.1f, 0.1f)),
                                  h * (sph::Real(k) + rng.uniform(-0.1f, 0.1f)));
                const sph::Vec3 v = velocity == CubeVelocity::Swirl
                                        ? sph::Vec3(-x[1], x[0], sph::Real(0.1))
                                        : sph::Vec3(0);
                p.add(x, v, m, sph::ParticleKind::Liquid);
            }
        }
    }
    for (auto& rho : p.densities()) rho = sph::Real(CUBE_REST_DENSITY);
    return p;
}

/// Volume options for the cube: voxel h / 2, support 3 h, the cube's rest density and
/// spacing; every grid (surface, density, vel) as VolumeOptions' defaults ask.
inline vdbio::VolumeOptions cubeVolumeOptions()
{
    vdbio::VolumeOptions o;
    o.voxelSize = 0.5 * CUBE_SPACING;
    o.kernelSupport = 3 * CUBE_SPACING;
    o.restDensity = CUBE_REST_DENSITY;
    o.particleSpacing = CUBE_SPACING;
    return o;
}

} // namespace bench
} // namespace ghostfx
