/// @file   PointIndexDensity.h
/// @brief  OpenVDB tools::PointIndexGrid neighbour search behind a plain API, for comparing
///         against ghostfx::sph::NeighborGrid in bench_neighbors.
/// @details The OpenVDB side of the issue "benchmark build + one density pass against
///          tools::PointIndexGrid doing the same queries". Every OpenVDB template is
///          instantiated in PointIndexDensity.cc only (shared/STACK.md: keep heavy OpenVDB
///          instantiations in their own translation unit), so this header includes no OpenVDB
///          tree code.
///
///          The density is the SPH sum rho_i = sum_j m_j W(|x_i - x_j|) over all j with
///          |x_i - x_j| < R (j == i included), computed in the same way, with the same kernel
///          and the same float operations, as the ghostfx side.
#pragma once

#include "ghostfx/sph/Kernels.h"
#include "ghostfx/sph/Types.h"

#include <cstddef>
#include <cstdint>
#include <memory>

namespace ghostfx {
namespace bench {

/// How a particle's candidate neighbours are fetched from the PointIndexGrid.
enum class PointIndexQuery {
    /// PointIndexIterator::searchAndUpdate(CoordBBox) over the voxels that the box
    /// [x - R, x + R] touches, then a distance test per candidate: what OpenVDB's own
    /// PointIndexFilter::searchAndApply does for radii below 8 voxels.
    BoxThenDistance,
    /// PointIndexIterator::worldSpaceSearchAndUpdate(x, R, ..., subvoxelAccuracy = true): OpenVDB
    /// filters voxels and points against the sphere; the kernel still needs r, so the distance
    /// is computed again for the survivors.
    RadialSubvoxel,
};

const char* queryName(PointIndexQuery query);

/// A tools::PointIndexGrid over a caller-owned position array. Not copyable: it owns its grid
/// through a unique_ptr.
class PointIndexDensity
{
public:
    /// @param voxelSize  voxel side of the index grid (m)
    explicit PointIndexDensity(double voxelSize);
    ~PointIndexDensity();

    /// tools::createPointIndexGrid over `count` positions (m). The array must outlive the
    /// queries: the grid stores indices into it, not copies.
    void build(const sph::Vec3* positions, std::size_t count);

    /// Bytes held by the index grid (Grid::memUsage()).
    std::size_t memoryBytes() const;
    double voxelSize() const { return mVoxelSize; }

    /// rho[i] = sum_j mass[j] W(r_ij) for every particle, parallel over i with TBB (one
    /// accessor and one iterator per task).
    /// @param kernel  smoothing kernel; its support radius R (m) is the search radius
    /// @param mass    particle masses (kg), indexed like the positions
    /// @param rho     output densities (kg/m^3), one per particle
    void density(const sph::CubicSplineKernel& kernel, const sph::Real* mass, sph::Real* rho,
                 PointIndexQuery query) const;

    /// Number of ordered pairs (i, j) with r_ij < radius (m), i == j included.
    std::uint64_t countPairs(sph::Real radius) const;

private:
    struct Impl;
    double mVoxelSize;
    std::unique_ptr<Impl> mImpl;
};

} // namespace bench
} // namespace ghostfx
