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

/// A particle lies within this many voxels (per axis 7.5: its voxel is at most 7 past the
/// leaf's first, plus half a voxel) of the centre of its leaf's first voxel.
const double LEAF_REACH_VOXELS = 7.5 * std::sqrt(3.0) + 0.5;

/// The rows of `near` whose points-grid leaf (voxel size of `xform`) this process owns.
sph::ParticleSet ownedLeaves(const sph::ParticleSet& near, const openvdb::math::Transform& xform,
                             const dist::MpiExchange& exchange)
{
    const double dx = xform.voxelSize()[0];
    std::vector<std::uint8_t> other(near.size(), 0);
    for (std::size_t i = 0; i < near.size(); ++i) {
        const sph::Vec3& x = near.positions()[i];
        // As OpenVDB buckets the point (PointsFile.cc passes positions in double).
        const openvdb::Coord voxel =
            xform.worldToIndexCellCentered(openvdb::Vec3d(x[0], x[1], x[2]));
        const openvdb::Coord origin = voxel & ~(LEAF_DIM - 1);
        const sph::Vec3 first(sph::Real(origin.x() * dx), sph::Real(origin.y() * dx),
                              sph::Real(origin.z() * dx));
        other[i] = exchange.decomposition().owner(first) != exchange.rank();
    }
    sph::ParticleSet mine = near;
    mine.removeIf(other);
    return mine;
}

} // namespace

BuiltGrids buildFrameGrids(dist::MpiExchange& exchange, const sph::ParticleSet& set,
                           const std::vector<sph::ParticleKind>& kinds,
                           const vdbio::PointsOptions* points, const vdbio::VolumeOptions* volumes,
                           FramePieceCounts* counts)
{
    vdbio::PointsOptions po;
    double width = 0;
    if (points) {
        po = *points;
        // Ghosts stay with their processes: only `kinds` travel.
        po.kinds.erase(std::remove_if(
                           po.kinds.begin(), po.kinds.end(),
                           [&](sph::ParticleKind k) {
            return std::find(kinds.begin(), kinds.end(), k) == kinds.end();
                           }),
                       po.kinds.end());
        if (po.kinds.empty()) po.kinds = kinds;
        if (po.voxelSize == 0) {
            std::vector<sph::Vec3> mine;
            const auto* halo = set.hasScalarChannel(sph::HALO_CHANNEL)
                                   ? &set.scalarChannel(sph::HALO_CHANNEL)
                                   : nullptr;
            for (std::size_t i = 0; i < set.size(); ++i) {
                if (halo && (*halo)[i] != sph::Real(0)) continue;
                if (std::find(po.kinds.begin(), po.kinds.end(), set.kinds()[i]) != po.kinds.end())
                    mine.push_back(set.positions()[i]);
            }
            const double local = mine.size() >= 2 ? vdbio::autoPointsVoxelSize(mine)
                                                  : std::numeric_limits<double>::infinity();
            po.voxelSize = exchange.minOf(local);
            if (!std::isfinite(po.voxelSize)) po.voxelSize = 0.1; // as writePointsFile does
        }
        width = LEAF_REACH_VOXELS * po.voxelSize;
    }
    if (volumes) width = std::max(width, vdbio::volumeReach(*volumes));

    std::size_t own = 0;
    const sph::ParticleSet near = exchange.surroundings(set, kinds, sph::Real(width), &own);
    if (counts) {
        counts->own = std::uint64_t(exchange.sumOf(double(own)));
        counts->copies = std::uint64_t(exchange.sumOf(double(near.size() - own)));
        counts->largest = std::uint64_t(exchange.maxOf(double(near.size())));
    }

    openvdb::GridPtrVec piece;
    if (points) {
        const auto xform = openvdb::math::Transform::createLinearTransform(po.voxelSize);
        const sph::ParticleSet leaves = ownedLeaves(near, *xform, exchange);
        // Every particle in exactly one piece: a leaf's particles all reach its owner.
        const double claimed = exchange.sumOf(double(leaves.size()));
        const double owned = exchange.sumOf(double(own));
        if (claimed != owned) {
            throw Error(msg("frame pieces: the points pieces hold ", claimed, " particles, the ",
                            "processes own ", owned, " (a piece is missing some of its leaves)"));
        }
        piece.push_back(vdbio::makePointsGrid(leaves, po));
    }
    if (volumes) {
        openvdb::GridPtrVec grids = vdbio::makeVolumeGrids(near, *volumes);
        vdbio::keepVoxelsIn(grids, exchange.decomposition().region(exchange.rank()));
        piece.insert(piece.end(), grids.begin(), grids.end());
    }

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

} // namespace cmd
} // namespace ghostfx
