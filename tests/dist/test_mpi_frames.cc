/// @file   test_mpi_frames.cc
/// @brief  A frame built in pieces over MPI ranks (cmd/DistributedFrames.h) against the same
///         frame built from the whole liquid by one process.
/// @details Every rank makes the same liquid from the same seed and keeps the particles its
///          region owns; buildFrameGrids then makes each rank's piece from its own particles and
///          copies of its neighbours' within the pieces' reach, and rank 0 merges them. The
///          reference is makePointsGrid / makeVolumeGrids over the whole liquid, on rank 0.
///          Tolerances: the points are the same particles, bucketed by the same voxel size
///          from the same double positions, so they must match exactly. A voxel of the surface
///          comes from minima and local filters of the particles within the reach, so it must
///          match exactly too; a voxel of the density and velocity grids sums the same
///          particles, possibly in another order: 1e-6 relative (float rounding of about 100
///          terms). The anisotropic surface's field sums the kernels near a leaf in the order
///          of the particles there, another order in a piece: float rounding (about 1e-7 of a
///          volume fraction) through the distance transform, measured at most 4e-6 of a voxel;
///          the bound is 1e-5 of a voxel.
#include "DistributedFrames.h"
#include "common/LatticeBall.h"

#include <ghostfx/sph/Random.h>

#include <openvdb/points/PointDataGrid.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace {

using namespace ghostfx;
using namespace ghostfx::sph;

int rankOfWorld()
{
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

/// A long jittered block of liquid (a wave on its top, so the surface is curved), a ball above
/// it, and a few lone droplets (spray): the same on every rank.
ParticleSet liquid(Real h)
{
    Rng rng(11);
    std::vector<Vec3> x;
    for (int i = 0; i < 120; ++i) {
        for (int k = 0; k < 6; ++k) {
            const int top = 8 + int(std::lround(3 * std::sin(i * 0.15)));
            for (int j = 0; j < top; ++j) {
                x.emplace_back(Real((i + 0.5) * h + rng.uniform(-0.1, 0.1) * h),
                               Real((j + 0.5) * h + rng.uniform(-0.1, 0.1) * h),
                               Real((k + 0.5) * h + rng.uniform(-0.1, 0.1) * h));
            }
        }
    }
    const Vec3 centre(Real(0.61), Real(0.2), Real(0.03));
    ghostfx::testing::addLatticeBall(x, centre, h, 5, 4.5 * h);
    for (int s = 0; s < 12; ++s)
        x.emplace_back(Real(rng.uniform(0.05, 1.15)), Real(0.3 + 0.02 * s), Real(0.03));
    ParticleSet set;
    set.addBatch(x, Real(1000) * h * h * h, ParticleKind::Liquid);
    for (std::size_t i = 0; i < set.size(); ++i) {
        const Vec3& p = set.positions()[i];
        set.velocities()[i] = Vec3(std::sin(Real(7) * p[0]), Real(0.1) * p[1], Real(-0.3));
        set.densities()[i] = Real(1000) + Real(i % 13);
    }
    return set;
}

struct Point
{
    Vec3 x;
    Vec3 v;
};

/// id -> (position, velocity) of a points grid made by makePointsGrid with "v" and "id".
std::map<std::int64_t, Point> pointsById(const openvdb::GridBase::Ptr& base)
{
    auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(base);
    EXPECT_TRUE(grid);
    std::map<std::int64_t, Point> out;
    if (!grid) return out;
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
        openvdb::points::AttributeHandle<openvdb::Vec3f> position(leaf->constAttributeArray("P"));
        openvdb::points::AttributeHandle<openvdb::Vec3f> velocity(leaf->constAttributeArray("v"));
        openvdb::points::AttributeHandle<std::int64_t> id(leaf->constAttributeArray("id"));
        for (auto voxel = leaf->beginValueOn(); voxel; ++voxel) {
            for (auto index = leaf->beginIndexVoxel(voxel.getCoord()); index; ++index) {
                const openvdb::Vec3d world = grid->transform().indexToWorld(
                    voxel.getCoord().asVec3d() + position.get(*index));
                const std::int64_t key = id.get(*index);
                EXPECT_EQ(out.count(key), 0u) << "point id " << key << " written twice";
                out[key] = Point{Vec3(world), Vec3(velocity.get(*index))};
            }
        }
    }
    return out;
}

void expectSameVectorGrid(const openvdb::Vec3SGrid& merged, const openvdb::Vec3SGrid& whole,
                          double relative)
{
    SCOPED_TRACE(whole.getName());
    EXPECT_EQ(merged.activeVoxelCount(), whole.activeVoxelCount());
    auto acc = merged.getConstAccessor();
    std::size_t differ = 0, off = 0;
    double largest = 0;
    for (auto it = whole.cbeginValueOn(); it; ++it) {
        if (!acc.isValueOn(it.getCoord())) {
            ++off;
            continue;
        }
        const double d = double((acc.getValue(it.getCoord()) - *it).length());
        const double scale = std::max(1e-12, double((*it).length()));
        largest = std::max(largest, d / scale);
        differ += d > relative * scale;
    }
    EXPECT_EQ(off, 0u) << "voxels active in the whole-liquid grid but not in the merged one";
    EXPECT_EQ(differ, 0u) << "largest relative difference " << largest;
}

void expectSameFloatGrid(const openvdb::FloatGrid& merged, const openvdb::FloatGrid& whole,
                         double relative, double absolute = 0)
{
    SCOPED_TRACE(whole.getName());
    EXPECT_EQ(merged.activeVoxelCount(), whole.activeVoxelCount());
    auto acc = merged.getConstAccessor();
    std::size_t differ = 0, off = 0;
    double largest = 0, largestAbsolute = 0;
    for (auto it = whole.cbeginValueOn(); it; ++it) {
        if (!acc.isValueOn(it.getCoord())) {
            ++off;
            continue;
        }
        const double d = std::abs(double(acc.getValue(it.getCoord())) - double(*it));
        const double scale = std::max(1e-12, std::abs(double(*it)));
        largest = std::max(largest, d / scale);
        largestAbsolute = std::max(largestAbsolute, d);
        differ += d > relative * scale + absolute;
    }
    EXPECT_EQ(off, 0u) << "voxels active in the whole-liquid grid but not in the merged one";
    EXPECT_EQ(differ, 0u) << "largest difference " << largest << " relative, " << largestAbsolute
                          << " absolute";
    if (whole.getGridClass() == openvdb::GRID_LEVEL_SET) {
        // Inside and outside away from the band: every voxel of the whole grid's bounding box.
        const openvdb::CoordBBox box = whole.evalActiveVoxelBoundingBox();
        auto wholeAcc = whole.getConstAccessor();
        std::size_t flipped = 0, seen = 0;
        for (auto c = box.begin(); c; ++c) {
            ++seen;
            flipped += (acc.getValue(*c) < 0) != (wholeAcc.getValue(*c) < 0);
        }
        EXPECT_EQ(flipped, 0u) << "of " << seen << " voxels, inside and outside differ";
    }
}

} // namespace

TEST(DistributedFrames, PiecesMergeToTheGridsOfTheWholeLiquid)
{
    const Real h = Real(0.01);
    const ParticleSet all = liquid(h);
    dist::MpiExchange exchange(MPI_COMM_WORLD, all.positions());
    const int rank = rankOfWorld();
    // This rank's own particles; every 50th is held by the next rank, as a particle that has
    // moved out of its holder's region since the last exchange is.
    ParticleSet mine = all;
    std::vector<std::uint8_t> other(mine.size());
    for (std::size_t i = 0; i < mine.size(); ++i) {
        int holder = exchange.decomposition().owner(mine.positions()[i]);
        if (mine.ids()[i] % 50 == 0) holder = (holder + 1) % exchange.ranks();
        other[i] = holder != rank;
    }
    mine.removeIf(other);

    vdbio::PointsOptions po;
    po.channels = {"v", "id", "density"};
    po.voxelSize = 0.02;
    vdbio::VolumeOptions vo;
    vo.voxelSize = 0.5 * h;
    vo.kernelSupport = 3 * h;
    vo.particleSpacing = h;
    // Points and volumes apart, so each piece's reach is its own (together, the larger).
    cmd::FramePieceCounts counts;
    const cmd::BuiltGrids points =
        cmd::buildFrameGrids(exchange, mine, {ParticleKind::Liquid}, &po, nullptr, &counts);
    // Only the particles in a leaf another process owns move (those near a cut, and every
    // 50th held away from its region).
    EXPECT_GT(counts.moved, all.size() / 50);
    EXPECT_LT(counts.moved, all.size() / 4);
    const cmd::BuiltGrids volumes =
        cmd::buildFrameGrids(exchange, mine, {ParticleKind::Liquid}, nullptr, &vo, &counts);
    EXPECT_EQ(counts.own, all.size());
    // Each piece holds the particles within the reach of its cuts, not the whole liquid.
    EXPECT_LT(counts.largest, all.size()) << "reach " << vdbio::volumeReach(vo) << " m";
    // The anisotropic surface (Yu and Turk), whose kernels reach farther.
    vdbio::VolumeOptions ao = vo;
    ao.surfaceMethod = vdbio::SurfaceMethod::Anisotropic;
    ao.density = ao.velocity = false;
    const cmd::BuiltGrids anisotropic =
        cmd::buildFrameGrids(exchange, mine, {ParticleKind::Liquid}, nullptr, &ao);
    if (rank != 0) {
        EXPECT_FALSE(points.points);
        EXPECT_TRUE(volumes.volumes.empty());
        return;
    }
    EXPECT_FALSE(volumes.points);
    EXPECT_TRUE(points.volumes.empty());

    const auto merged = pointsById(points.points);
    const auto whole = pointsById(vdbio::makePointsGrid(all, po));
    ASSERT_EQ(merged.size(), all.size());
    ASSERT_EQ(whole.size(), all.size());
    for (const auto& [id, p] : whole) {
        const auto it = merged.find(id);
        ASSERT_NE(it, merged.end()) << "point id " << id << " missing";
        EXPECT_EQ(it->second.x, p.x) << "point id " << id;
        EXPECT_EQ(it->second.v, p.v) << "point id " << id;
    }

    const openvdb::GridPtrVec anisotropicWhole = vdbio::makeVolumeGrids(all, ao);
    ASSERT_EQ(anisotropic.volumes.size(), 1u);
    expectSameFloatGrid(*openvdb::gridPtrCast<openvdb::FloatGrid>(anisotropic.volumes[0]),
                        *openvdb::gridPtrCast<openvdb::FloatGrid>(anisotropicWhole[0]), 0.0,
                        1e-5 * vo.voxelSize);

    const openvdb::GridPtrVec reference = vdbio::makeVolumeGrids(all, vo);
    ASSERT_EQ(volumes.volumes.size(), reference.size());
    for (std::size_t g = 0; g < reference.size(); ++g) {
        ASSERT_EQ(volumes.volumes[g]->getName(), reference[g]->getName());
        if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(reference[g])) {
            const double tolerance = f->getGridClass() == openvdb::GRID_LEVEL_SET ? 0.0 : 1e-6;
            expectSameFloatGrid(*openvdb::gridPtrCast<openvdb::FloatGrid>(volumes.volumes[g]), *f,
                                tolerance);
        } else {
            expectSameVectorGrid(*openvdb::gridPtrCast<openvdb::Vec3SGrid>(volumes.volumes[g]),
                                 *openvdb::gridPtrCast<openvdb::Vec3SGrid>(reference[g]), 1e-6);
        }
    }
}
