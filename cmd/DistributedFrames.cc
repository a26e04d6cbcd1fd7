/// @file   DistributedFrames.cc
#include "DistributedFrames.h"

#include <ghostfx/sph/Exceptions.h>

#include <openvdb/math/Transform.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ghostfx {
namespace cmd {

namespace {

/// Voxels per leaf edge of OpenVDB's standard trees, the points grid's among them.
constexpr int LEAF_DIM = int(openvdb::FloatTree::LeafNodeType::DIM);

/// The process that owns the points-grid leaf (voxel size of `xform`) holding x: the one whose
/// region holds the centre of the leaf's first voxel.
int leafOwner(const sph::Vec3& x, const openvdb::math::Transform& xform,
              const sph::DomainDecomposition& parts)
{
    const double dx = xform.voxelSize()[0];
    // As OpenVDB buckets the point (PointsFile.cc passes positions in double).
    const openvdb::Coord voxel = xform.worldToIndexCellCentered(openvdb::Vec3d(x[0], x[1], x[2]));
    const openvdb::Coord origin = voxel & ~(LEAF_DIM - 1);
    return parts.owner(sph::Vec3(sph::Real(origin.x() * dx), sph::Real(origin.y() * dx),
                                 sph::Real(origin.z() * dx)));
}

/// The voxel size every process's points grid shares: the smallest of their automatic sizes
/// over their own particles of `kinds` (halo copies left out).
double sharedPointsVoxelSize(dist::MpiExchange& exchange, const sph::ParticleSet& set,
                             const std::vector<sph::ParticleKind>& kinds)
{
    std::vector<sph::Vec3> mine;
    const auto* halo =
        set.hasScalarChannel(sph::HALO_CHANNEL) ? &set.scalarChannel(sph::HALO_CHANNEL) : nullptr;
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (halo && (*halo)[i] != sph::Real(0)) continue;
        if (std::find(kinds.begin(), kinds.end(), set.kinds()[i]) != kinds.end())
            mine.push_back(set.positions()[i]);
    }
    const double local = mine.size() >= 2 ? vdbio::autoPointsVoxelSize(mine)
                                          : std::numeric_limits<double>::infinity();
    const double voxelSize = exchange.minOf(local);
    return std::isfinite(voxelSize) ? voxelSize : 0.1; // as writePointsFile does
}

/// `points` for a distributed frame: only the kinds that travel (`kinds`; ghosts stay with
/// their processes), and one voxel size on every process.
vdbio::PointsOptions distributedPointsOptions(dist::MpiExchange& exchange,
                                              const sph::ParticleSet& set,
                                              const std::vector<sph::ParticleKind>& kinds,
                                              const vdbio::PointsOptions& points)
{
    vdbio::PointsOptions po = points;
    po.kinds.erase(std::remove_if(
                       po.kinds.begin(), po.kinds.end(),
                       [&](sph::ParticleKind k) {
        return std::find(kinds.begin(), kinds.end(), k) == kinds.end();
                       }),
                   po.kinds.end());
    if (po.kinds.empty()) po.kinds = kinds;
    if (po.voxelSize == 0) po.voxelSize = sharedPointsVoxelSize(exchange, set, po.kinds);
    return po;
}

/// This process's piece of the points grid: each particle sent to the process owning its leaf,
/// so no leaf is split between pieces. Counts the particles it sent in `mine`.
openvdb::GridBase::Ptr pointsPiece(dist::MpiExchange& exchange, const sph::ParticleSet& set,
                                   const vdbio::PointsOptions& po, FramePieceCounts& mine)
{
    const auto xform = openvdb::math::Transform::createLinearTransform(po.voxelSize);
    const sph::DomainDecomposition& parts = exchange.decomposition();
    // Attributes summed over neighbours are computed here, over copies of the other
    // processes' particles near this region, before the points move.
    sph::ParticleSet estimated;
    const sph::ParticleSet* source = &set;
    if (vdbio::needsNeighbourAttributes(set, po)) {
        std::size_t own = 0;
        const sph::ParticleSet near = exchange.surroundings(
            set, po.kinds, sph::Real(vdbio::neighbourAttributeReach(set, po)), &own);
        estimated = vdbio::withNeighbourAttributes(near, own, po);
        source = &estimated;
    }
    std::size_t sent = 0;
    const sph::ParticleSet leaves = exchange.redistribute(
        *source, po.kinds, [&](const sph::Vec3& x) { return leafOwner(x, *xform, parts); },
        &sent);
    mine.moved = sent;
    return vdbio::makePointsGrid(leaves, po);
}

/// This process's piece of the volume grids: built from its particles of `kinds` and copies of
/// those near its region, then cut to the region. Counts them in `mine`.
openvdb::GridPtrVec volumesPiece(dist::MpiExchange& exchange, const sph::ParticleSet& set,
                                 const std::vector<sph::ParticleKind>& kinds,
                                 const vdbio::VolumeOptions& volumes, FramePieceCounts& mine)
{
    std::size_t own = 0;
    const sph::ParticleSet near =
        exchange.surroundings(set, kinds, sph::Real(vdbio::volumeReach(volumes)), &own);
    mine.own = own;
    mine.copies = near.size() - own;
    mine.largest = near.size();
    openvdb::GridPtrVec grids = vdbio::makeVolumeGrids(near, volumes);
    vdbio::keepVoxelsIn(grids, exchange.decomposition().region(exchange.rank()));
    return grids;
}

/// Every process's `mine`, summed (the largest: the most) into `counts`.
void sumCounts(dist::MpiExchange& exchange, const FramePieceCounts& mine, FramePieceCounts& counts)
{
    counts.own = std::uint64_t(exchange.sumOf(double(mine.own)));
    counts.copies = std::uint64_t(exchange.sumOf(double(mine.copies)));
    counts.largest = std::uint64_t(exchange.maxOf(double(mine.largest)));
    counts.moved = std::uint64_t(exchange.sumOf(double(mine.moved)));
}

/// Every process's `piece` (a points grid first if `points`, then the volume grids if
/// `volumes`) sent to process 0 and merged there; empty grids elsewhere.
BuiltGrids mergePieces(dist::MpiExchange& exchange, const openvdb::GridPtrVec& piece, bool points,
                       bool volumes)
{
    std::vector<openvdb::GridBase::Ptr> pointPieces;
    std::vector<openvdb::GridPtrVec> volumePieces;
    exchange.collect(vdbio::gridsToBytes(piece), [&](int, const std::string& bytes) {
        openvdb::GridPtrVec grids =
            bytes.empty() ? openvdb::GridPtrVec() : vdbio::gridsFromBytes(bytes);
        if (grids.size() != piece.size())
            throw Error(msg("frame pieces: a process sent ", grids.size(), " grids, expected ",
                            piece.size()));
        if (points) {
            pointPieces.push_back(grids.front());
            grids.erase(grids.begin());
        }
        if (volumes) volumePieces.push_back(std::move(grids));
    });
    BuiltGrids out;
    if (exchange.rank() != 0) return out;
    if (points) out.points = vdbio::mergePointsGrids(pointPieces);
    if (volumes) out.volumes = vdbio::mergeVolumeGrids(std::move(volumePieces));
    return out;
}

} // namespace

BuiltGrids buildFrameGrids(dist::MpiExchange& exchange, const sph::ParticleSet& set,
                           const std::vector<sph::ParticleKind>& kinds,
                           const vdbio::PointsOptions* points, const vdbio::VolumeOptions* volumes,
                           FramePieceCounts* counts)
{
    openvdb::GridPtrVec piece;
    FramePieceCounts mine;
    if (points) {
        const vdbio::PointsOptions po = distributedPointsOptions(exchange, set, kinds, *points);
        piece.push_back(pointsPiece(exchange, set, po, mine));
    }
    if (volumes) {
        const openvdb::GridPtrVec grids = volumesPiece(exchange, set, kinds, *volumes, mine);
        piece.insert(piece.end(), grids.begin(), grids.end());
    }
    if (counts) sumCounts(exchange, mine, *counts);
    return mergePieces(exchange, piece, points != nullptr, volumes != nullptr);
}

} // namespace cmd
} // namespace ghostfx
