/// @file   test_frame_pieces.cc
/// @brief  A frame's grids in pieces (FrameFiles.h: keepVoxelsIn, mergeVolumeGrids,
///         mergePointsGrids, gridsToBytes) in one process: pieces cut from the whole grids
///         merge back to them exactly; points pieces that share a leaf are refused. The pieces
///         of a run over MPI ranks, each built from its own surroundings, are checked in
///         tests/dist/test_mpi_frames.cc.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/Random.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include "common/Expect.h"
#include "common/LatticeBall.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace ghostfx;
using namespace ghostfx::sph;

namespace {

/// A jittered block with a ball on it: about 3,000 particles at h = 1 cm.
ParticleSet blockAndBall(Real h)
{
    Rng rng(5);
    std::vector<Vec3> x;
    for (int i = 0; i < 30; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 10; ++k)
                x.emplace_back(Real((i + 0.5 + rng.uniform(-0.1, 0.1)) * h),
                               Real((j + 0.5 + rng.uniform(-0.1, 0.1)) * h),
                               Real((k + 0.5 + rng.uniform(-0.1, 0.1)) * h));
    const Vec3 centre(Real(0.15), Real(0.14), Real(0.05));
    ghostfx::testing::addLatticeBall(x, centre, h, 4, 3.5 * h);
    ParticleSet set;
    set.addBatch(x, Real(1000) * h * h * h, ParticleKind::Liquid);
    for (std::size_t i = 0; i < set.size(); ++i)
        set.velocities()[i] = Vec3(Real(0.1) * set.positions()[i][1], 0, Real(-1));
    return set;
}

Aabb halfSpace(int axis, Real cut, bool upper)
{
    Aabb box{Vec3(-std::numeric_limits<Real>::max()), Vec3(std::numeric_limits<Real>::max())};
    (upper ? box.min : box.max)[axis] = cut;
    return box;
}

} // namespace

TEST(FramePieces, VolumesCutToRegionsMergeBackToTheWholeGrids)
{
    const Real h = Real(0.01);
    const ParticleSet all = blockAndBall(h);
    vdbio::VolumeOptions vo;
    vo.voxelSize = 0.5 * h;
    vo.kernelSupport = 3 * h;
    vo.particleSpacing = h;
    const openvdb::GridPtrVec whole = vdbio::makeVolumeGrids(all, vo);

    // Three pieces: x below 0.1 m, between, above 0.2 m (the ball straddles the upper cut).
    std::vector<openvdb::GridPtrVec> pieces;
    const Aabb regions[] = {halfSpace(0, Real(0.1), false), halfSpace(0, Real(0.1), true),
                            halfSpace(0, Real(0.2), true)};
    for (int p = 0; p < 3; ++p) {
        Aabb region = regions[p];
        if (p == 1) region.max[0] = Real(0.2);
        openvdb::GridPtrVec grids = vdbio::makeVolumeGrids(all, vo);
        vdbio::keepVoxelsIn(grids, region);
        // Through bytes, as between processes.
        pieces.push_back(vdbio::gridsFromBytes(vdbio::gridsToBytes(grids)));
    }
    const openvdb::GridPtrVec merged = vdbio::mergeVolumeGrids(pieces);
    ASSERT_EQ(merged.size(), whole.size());
    for (std::size_t g = 0; g < whole.size(); ++g) {
        SCOPED_TRACE(whole[g]->getName());
        EXPECT_EQ(merged[g]->getName(), whole[g]->getName());
        EXPECT_EQ(merged[g]->activeVoxelCount(), whole[g]->activeVoxelCount());
        if (auto w = openvdb::gridPtrCast<openvdb::FloatGrid>(whole[g])) {
            auto m = openvdb::gridPtrCast<openvdb::FloatGrid>(merged[g]);
            ASSERT_TRUE(m);
            auto acc = m->getConstAccessor();
            std::size_t differ = 0;
            for (auto it = w->cbeginValueOn(); it; ++it)
                differ += !acc.isValueOn(it.getCoord()) || acc.getValue(it.getCoord()) != *it;
            EXPECT_EQ(differ, 0u);
            if (w->getGridClass() == openvdb::GRID_LEVEL_SET) {
                // The signs away from the band, filled anew from the merged band.
                auto wacc = w->getConstAccessor();
                std::size_t flipped = 0;
                const openvdb::CoordBBox box = w->evalActiveVoxelBoundingBox();
                for (auto c = box.begin(); c; ++c)
                    flipped += (acc.getValue(*c) < 0) != (wacc.getValue(*c) < 0);
                EXPECT_EQ(flipped, 0u);
            }
        } else {
            auto w3 = openvdb::gridPtrCast<openvdb::Vec3SGrid>(whole[g]);
            auto m3 = openvdb::gridPtrCast<openvdb::Vec3SGrid>(merged[g]);
            ASSERT_TRUE(w3 && m3);
            auto acc = m3->getConstAccessor();
            std::size_t differ = 0;
            for (auto it = w3->cbeginValueOn(); it; ++it)
                differ += !acc.isValueOn(it.getCoord()) || acc.getValue(it.getCoord()) != *it;
            EXPECT_EQ(differ, 0u);
        }
    }
}

TEST(FramePieces, PointsPiecesMergeWhenTheirLeavesAreDisjointAndAreRefusedOtherwise)
{
    const Real h = Real(0.01);
    const ParticleSet all = blockAndBall(h);
    vdbio::PointsOptions po;
    po.channels = {"v", "id"};
    po.voxelSize = 0.02; // leaves 0.16 m wide, the first from voxel 0 (x from -0.01 m)
    auto piece = [&](Real lo, Real hi) {
        ParticleSet part = all;
        std::vector<std::uint8_t> drop(part.size());
        for (std::size_t i = 0; i < part.size(); ++i)
            drop[i] = !(part.positions()[i][0] >= lo && part.positions()[i][0] < hi);
        part.removeIf(drop);
        return vdbio::makePointsGrid(part, po);
    };
    const Real big = std::numeric_limits<Real>::max();
    // Cut at a leaf boundary (voxel 8 starts at x = 7.5 voxels = 0.15 m): disjoint leaves.
    const openvdb::GridBase::Ptr merged =
        vdbio::mergePointsGrids({piece(-big, Real(0.15)), piece(Real(0.15), big)});
    const openvdb::GridBase::Ptr whole = vdbio::makePointsGrid(all, po);
    EXPECT_EQ(merged->metaValue<std::int64_t>("point_count"), std::int64_t(all.size()));
    EXPECT_EQ(merged->activeVoxelCount(), whole->activeVoxelCount());
    // Cut through a leaf: the two pieces share it.
    const std::string error = ghostfx::testing::errorOf<ValueError>([&] {
        vdbio::mergePointsGrids({piece(-big, Real(0.1)), piece(Real(0.1), big)});
    });
    EXPECT_TRUE(ghostfx::testing::contains(error, "two pieces hold the leaf")) << error;
}
