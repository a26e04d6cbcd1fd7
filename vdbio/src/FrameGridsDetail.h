/// @file   FrameGridsDetail.h
/// @brief  Private interface between the frame-output translation units of vdbio.
/// @details Each heavy OpenVDB instantiation lives in its own .cc (STACK.md, compile times):
///          SurfaceGrid.cc (ParticlesToLevelSet + LevelSetFilter), AnisotropicSurface.cc
///          (anisotropic-kernel field + fast sweeping), ParticleGrids.cc (gathered density /
///          velocity / channel fog grids), PointsFile.cc (PointDataGrid). VolumeFile.cc validates
///          options, selects particles and calls these.
#pragma once

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {
namespace detail {

using FloatLeaf = openvdb::FloatTree::LeafNodeType;
constexpr int LEAF_DIM = int(FloatLeaf::DIM);           // 8 voxels per leaf edge
constexpr int LEAF_VOXELS = int(FloatLeaf::NUM_VALUES); // 512

/// Voxel index range [lo, hi] on one axis whose centres i * dx lie within `reach` (m) of `x`.
inline void voxelRange(double x, double reach, double invDx, int& lo, int& hi)
{
    lo = int(std::ceil((x - reach) * invDx));
    hi = int(std::floor((x + reach) * invDx));
}

/// The voxels of the leaf at `origin` whose centres lie within `reach[d]` (m) of `x` on every
/// axis d, as offsets [lo[d], hi[d]] inside the leaf; false when that box misses the leaf.
inline bool boxInLeaf(const double x[3], const double reach[3], double invDx,
                      const openvdb::Coord& origin, int lo[3], int hi[3])
{
    for (int d = 0; d < 3; ++d) {
        voxelRange(x[d], reach[d], invDx, lo[d], hi[d]);
        lo[d] = std::max(lo[d] - origin[d], 0);
        hi[d] = std::min(hi[d] - origin[d], LEAF_DIM - 1);
        if (lo[d] > hi[d]) return false;
    }
    return true;
}

/// The centre of the leaf at `origin`, midway between its outermost voxel centres (m).
inline sph::Vec3 leafCentre(const openvdb::Coord& origin, double dx)
{
    return sph::Vec3(sph::Real((origin.x() + 0.5 * (LEAF_DIM - 1)) * dx),
                     sph::Real((origin.y() + 0.5 * (LEAF_DIM - 1)) * dx),
                     sph::Real((origin.z() + 0.5 * (LEAF_DIM - 1)) * dx));
}

/// Half the diagonal of a leaf between its outermost voxel centres (m).
inline double leafHalfDiagonal(double dx) { return 0.5 * std::sqrt(3.0) * (LEAF_DIM - 1) * dx; }

/// Indices of the particles whose kind is in `kinds`, in increasing order.
std::vector<sph::Index> selectKinds(const sph::ParticleSet& particles,
                                    const std::vector<sph::ParticleKind>& kinds);

/// Comma-separated list of names, for error messages.
std::string joinNames(const std::vector<std::string>& names);

/// options.validate(), its message prefixed by `where` unless `where` is the output's own name
/// (`ownName`, which validate() already starts with).
template <typename Options>
void validateFor(const Options& options, const std::string& where, const char* ownName)
{
    try {
        options.validate();
    } catch (const ValueError& e) {
        if (where == ownName) throw;
        throw ValueError(msg(where, ": ", e.what()));
    }
}

/// The empty level set "surface" both surface methods fill: voxel size, half width, class,
/// units and particle spacing from `options`.
openvdb::FloatGrid::Ptr makeEmptySurfaceGrid(const VolumeOptions& options);

/// Liquid surface level set "surface" of the selected particles (options already validated).
openvdb::FloatGrid::Ptr makeSurfaceGrid(const sph::ParticleSet& particles,
                                        const std::vector<sph::Index>& selection,
                                        const VolumeOptions& options);

/// Liquid surface level set "surface" of the selected particles by anisotropic kernels (Yu and
/// Turk 2013; AnisotropicSurface.cc): same name, class, transform, background and metadata as
/// makeSurfaceGrid, plus "surface_method" = "anisotropic". Options already validated.
openvdb::FloatGrid::Ptr makeAnisotropicSurfaceGrid(const sph::ParticleSet& particles,
                                                   const std::vector<sph::Index>& selection,
                                                   const VolumeOptions& options);

/// Origins (multiples of 8) of the 8^3 leaves whose voxels (centred at (i,j,k) * dx) meet the
/// box of half side `reach` (m) about any of the particles x[order[k]] (or reaches[order[k]]
/// where `reaches` is given). `order` should list neighbours close together (a NeighborGrid's
/// cell order): the list is built per block of 4096 and merged, sorted and unique, so it does
/// not depend on the thread count.
std::vector<openvdb::Coord> leavesNearParticles(const std::vector<sph::Vec3>& x,
                                                const std::vector<sph::Index>& order, double dx,
                                                double reach,
                                                const std::vector<sph::Real>* reaches = nullptr);

/// "density", "vel" and the scalar channel grids, as asked by `options` (already validated;
/// channel names already checked), gathered on one shared sparse topology.
openvdb::GridPtrVec makeParticleGrids(const sph::ParticleSet& particles,
                                      const std::vector<sph::Index>& selection,
                                      const VolumeOptions& options);

/// Write `grids` with `fileMetadata` to the .vdb `path` atomically (AtomicFile.h); IoError
/// "<what> '<path>': cannot write (...)" on an OpenVDB or stream failure.
void writeVdbFile(const std::string& path, const char* what, const openvdb::GridCPtrVec& grids,
                  const openvdb::MetaMap& fileMetadata);

/// Metadata every ghostfx grid carries: creator, full float precision on write.
void setCommonGridMetadata(openvdb::GridBase& grid);

/// Throw IoError "<what> '<path>': folder '<dir>' does not exist" (or is not a folder), so a
/// wrong output path is reported before any grid is built and without the temporary name.
void checkOutputFolder(const std::string& path, const char* what);

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
