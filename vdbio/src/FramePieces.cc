/// @file   FramePieces.cc
/// @brief  A frame's volumes built in pieces (one per process of a distributed run) and merged:
///         the reach that makes a piece exact, the cut to a region, the merge, and grids as
///         bytes.
/// @details A piece is built by makeVolumeGrids from the particles within volumeReach() of
///          its region, so every voxel centre in the region gets the value the whole set would
///          give it; keepVoxelsIn() deactivates the rest, and mergeVolumeGrids() copies the
///          pieces' active values into fresh grids. Inactive values are only the sign of a level
///          set away from its band, and tools::signedFloodFill sets them from the merged band.
#include "FrameGridsDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <openvdb/io/Stream.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace ghostfx {
namespace vdbio {

namespace {

/// Index bounds beyond any grid ghostfx builds (OpenVDB's coordinates are 32-bit).
constexpr int INDEX_LIMIT = 1 << 28;

/// The smallest voxel index i whose centre i * dx is at or above `bound`.
int firstIndexAtOrAbove(double bound, double dx)
{
    if (bound <= -INDEX_LIMIT * dx) return -INDEX_LIMIT;
    if (bound >= INDEX_LIMIT * dx) return INDEX_LIMIT;
    int i = int(std::ceil(bound / dx));
    while (double(i - 1) * dx >= bound) --i;
    while (double(i) * dx < bound) ++i;
    return i;
}

template <typename GridT>
void copyActiveValues(GridT& into, const GridT& from)
{
    auto acc = into.getAccessor();
    for (auto it = from.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) {
            acc.setValueOn(it.getCoord(), *it);
        } else {
            into.tree().fill(it.getBoundingBox(), *it, true);
        }
    }
}

/// Deactivate the voxels outside `box` and drop the leaves that lie wholly outside. Only the
/// existing leaves are visited: OpenVDB's Tree::clip would fill the whole outside of the
/// box (an infinite slab's cut plane through every internal node) with background leaves.
template <typename GridT>
void keepActiveIn(GridT& grid, const openvdb::CoordBBox& box)
{
    using LeafT = typename GridT::TreeType::LeafNodeType;
    grid.tree().voxelizeActiveTiles();
    std::vector<openvdb::Coord> outside;
    for (auto leaf = grid.tree().beginLeaf(); leaf; ++leaf) {
        const openvdb::CoordBBox bounds = leaf->getNodeBoundingBox();
        if (box.isInside(bounds)) continue;
        if (!box.hasOverlap(bounds)) {
            outside.push_back(leaf->origin());
            continue;
        }
        for (auto v = leaf->beginValueOn(); v; ++v) {
            if (!box.isInside(v.getCoord())) v.setValueOff();
        }
    }
    for (const openvdb::Coord& origin : outside) {
        delete grid.tree().template stealNode<LeafT>(origin, grid.background(), false);
    }
}

} // namespace

double volumeReach(const VolumeOptions& o)
{
    double reach = 0.0;
    const double h = o.particleSpacing;
    const int w = o.surfaceHalfWidthVoxels;
    if (o.surface && o.surfaceMethod == SurfaceMethod::Spheres) {
        const double dx = o.voxelSize;
        // Union of spheres (SurfaceGrid.cc): a kept voxel's value comes from a particle within
        // R of it, rasterised if its voxel lies within `shell` voxels of the uncovered voxels
        // N next to the coverage mask (the voxel centres within r of a particle); whether a
        // voxel is deep interior depends on N within m voxels (m < shell); the interior trim
        // reads the sign w voxels around.
        const double R = (o.surfaceRadiusSpacings + o.surfaceClosingSpacings) * h;
        const double r = o.surfaceRadiusSpacings * h;
        const int m = int(std::ceil(R / dx + w + 0.5));
        const int shell = std::max(int(std::ceil(R / dx + std::sqrt(3.0) * w + 0.5)),
                                   int(std::ceil(R / dx + 0.5)) + m);
        double voxels = std::ceil((R + r) / dx) + shell + 1 + w;
        // Filters: a curvature pass reads one voxel around, each re-normalisation and band
        // update (after every pass and every half-voxel offset step) two more.
        const double erosion = std::abs(R - o.surfaceOffsetSpacings * h);
        voxels += 3.0 * o.surfaceSmoothingIterations + 2.0 * std::ceil(erosion / (0.5 * dx)) + 1;
        reach = std::max(reach, voxels * dx);
    } else if (o.surface) {
        // Anisotropic kernels (AnisotropicSurface.cc): a kernel's centre moves at most
        // lambda r from its particle and its shape reads the neighbours within r; its largest
        // semi-axis is k_s sigma_max h_k, where the covariance's largest eigenvalue is at most
        // the second moment r^2 about the particle (sigma_max = r^2 / 0.15 r^2), or k_n h_k for
        // a lone particle. The band and the fast sweeping reach w + 1 voxels past the
        // iso-surface.
        const double rn = o.anisotropicNeighborhoodSpacings * h;
        const double hk = o.anisotropicKernelSpacings * h;
        const double kernel = hk * std::max(o.anisotropicScale / 0.15, o.anisotropicIsolatedScale);
        reach =
            std::max(reach, (1.0 + o.anisotropicSmoothing) * rn + kernel + (w + 2) * o.voxelSize);
    }
    if (o.density || o.velocity || !o.scalarChannels.empty()) {
        // A gathered voxel sums the particles within the kernel support of its centre (or
        // their own, up to MAX_SUPPORT_SCALE times it).
        const double R = o.supportChannel.empty()
                             ? o.kernelSupport
                             : VolumeOptions::MAX_SUPPORT_SCALE * o.kernelSupport;
        reach = std::max(reach, R + o.fogVoxelSize());
    }
    return reach;
}

void keepVoxelsIn(openvdb::GridPtrVec& grids, const sph::Aabb& region)
{
    for (const openvdb::GridBase::Ptr& grid : grids) {
        const double dx = grid->voxelSize()[0];
        openvdb::CoordBBox box;
        for (int a = 0; a < 3; ++a) {
            box.min()[a] = firstIndexAtOrAbove(double(region.min[a]), dx);
            box.max()[a] = firstIndexAtOrAbove(double(region.max[a]), dx) - 1;
        }
        if (box.empty()) {
            grid->clear();
        } else if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(grid)) {
            keepActiveIn(*f, box);
        } else if (auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid)) {
            keepActiveIn(*v, box);
        } else {
            throw ValueError(msg("volume piece: grid '", grid->getName(), "' of type ",
                                 grid->type(), ": expected float or vec3s"));
        }
    }
}

openvdb::GridPtrVec mergeVolumeGrids(std::vector<openvdb::GridPtrVec> pieces)
{
    if (pieces.empty()) throw ValueError("volume merge: no pieces");
    // Fresh grids (the first piece's metadata, transform and background): only the pieces'
    // active values go in, so nothing a piece computed outside its region survives.
    openvdb::GridPtrVec merged;
    for (const openvdb::GridBase::Ptr& grid : pieces.front())
        merged.push_back(grid->copyGridWithNewTree());
    for (std::size_t p = 0; p < pieces.size(); ++p) {
        if (pieces[p].size() != merged.size()) {
            throw ValueError(msg("volume merge: piece ", p, " has ", pieces[p].size(),
                                 " grids, the first ", merged.size()));
        }
        for (std::size_t g = 0; g < merged.size(); ++g) {
            openvdb::GridBase& into = *merged[g];
            const openvdb::GridBase& from = *pieces[p][g];
            if (from.getName() != into.getName() || from.type() != into.type()
                || !(from.transform() == into.transform())) {
                throw ValueError(msg("volume merge: piece ", p, "'s grid '", from.getName(),
                                     "' does not match the first piece's '", into.getName(),
                                     "' (name, type and transform)"));
            }
            if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(merged[g])) {
                copyActiveValues(*f, static_cast<const openvdb::FloatGrid&>(from));
            } else if (auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(merged[g])) {
                copyActiveValues(*v, static_cast<const openvdb::Vec3SGrid&>(from));
            } else {
                throw ValueError(msg("volume merge: grid '", from.getName(), "' of type ",
                                     from.type(), ": expected float or vec3s"));
            }
        }
        pieces[p].clear(); // its memory goes as soon as it is merged
    }
    for (const openvdb::GridBase::Ptr& grid : merged) {
        auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
        if (f && f->getGridClass() == openvdb::GRID_LEVEL_SET) {
            openvdb::tools::signedFloodFill(f->tree());
            openvdb::tools::pruneLevelSet(f->tree());
        } else if (f) {
            openvdb::tools::pruneInactive(f->tree());
        } else if (auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid)) {
            openvdb::tools::pruneInactive(v->tree());
        }
    }
    return merged;
}

std::string gridsToBytes(const openvdb::GridPtrVec& grids)
{
    std::ostringstream out(std::ios::binary);
    openvdb::io::Stream(out).write(openvdb::GridCPtrVec(grids.begin(), grids.end()));
    if (!out) throw IoError("grids to bytes: the stream failed");
    return out.str();
}

openvdb::GridPtrVec gridsFromBytes(const std::string& bytes)
{
    std::istringstream in(bytes, std::ios::binary);
    openvdb::io::Stream stream(in);
    openvdb::GridPtrVecPtr grids = stream.getGrids();
    return grids ? *grids : openvdb::GridPtrVec();
}

} // namespace vdbio
} // namespace ghostfx
