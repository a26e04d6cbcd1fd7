/// @file   SphereSurface.h
/// @brief  Test helpers of the surface tests: a Poisson-disk liquid sphere, and where a level
///         set's zero crossings lie relative to a sphere.
#pragma once

#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/PoissonSampler.h>
#include <ghostfx/sph/SphDensity.h>

#include <openvdb/openvdb.h>

#include <cstdint>
#include <vector>

namespace ghostfx {
namespace testing {

/// Poisson-disk samples of a liquid sphere and their mass.
struct LiquidSphere
{
    sph::SampleSet samples;
    sph::Real mass = 0; ///< per particle (kg)
};

/// A Poisson-disk liquid sphere ([SB12] Sec. 4.5) of radius `radius` about the origin at
/// spacing `h`, sampled from a level set of voxel `voxel`. Its mass gives rest density `rho0`
/// (kg/m^3, [SB12] Sec. 4.6) on average over the particles deeper than the kernel support
/// `support` (the ones with a full neighbourhood; in a small sphere the surface layer holds
/// most particles). Lengths in m.
inline LiquidSphere poissonLiquidSphere(double h, double radius, double voxel, double support,
                                        double rho0)
{
    LiquidSphere sphere;
    sphere.samples = sph::PoissonDiskSampler(sph::PoissonSettings::forSpacing(sph::Real(h)))
                         .sampleVolume(sph::makeLevelSet(sph::makeSphereLevelSet(
                             sph::Vec3(0), sph::Real(radius), sph::Real(voxel))));
    const std::vector<sph::Vec3>& x = sphere.samples.positions;
    std::vector<std::uint8_t> interior(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
        interior[i] = x[i].length() < sph::Real(radius - support);
    sphere.mass = sph::massForRestDensity(x, sph::CubicSplineKernel(sph::Real(support)),
                                          sph::Real(rho0), interior);
    return sphere;
}

/// Distance from a sphere of radius `radius` (m) about the origin of every zero crossing of
/// `phi` (m): on each voxel edge from an active inside voxel (phi < 0) to a neighbour outside
/// (phi >= 0), the crossing found by linear interpolation. In the order of the active voxels,
/// then the six neighbours (+x, -x, +y, -y, +z, -z).
inline std::vector<double> radialCrossingErrors(const openvdb::FloatGrid& phi, double radius)
{
    std::vector<double> errors;
    const auto acc = phi.getConstAccessor();
    const openvdb::Coord steps[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                     {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    for (auto it = phi.cbeginValueOn(); it; ++it) {
        const double a = *it;
        if (a >= 0) continue;
        for (const openvdb::Coord& step : steps) {
            const double b = acc.getValue(it.getCoord() + step);
            if (b < 0) continue;
            const openvdb::Vec3d xa = phi.indexToWorld(it.getCoord());
            const openvdb::Vec3d xb = phi.indexToWorld(it.getCoord() + step);
            errors.push_back((xa + (a / (a - b)) * (xb - xa)).length() - radius);
        }
    }
    return errors;
}

} // namespace testing
} // namespace ghostfx
