/// @file   test_mask_dilation.cc
/// @brief  dilateMaxNorm (vdbio/MaskDilation.h) against OpenVDB's own k iterations of
///         26-neighbour dilation: the same active voxels, for k below, at and above a leaf;
///         dilateFaces against NN_FACE, on masks and, in place, on a level set's band.
/// @details The masks: scattered single voxels (every bit position of a word exercised,
///          leaves apart and adjacent, negative coordinates) and a thick spherical shell like
///          the surface's band (SurfaceGrid.cc dilates such shells by 1, 3, 5 and 8).
#include <ghostfx/sph/Random.h>
#include <ghostfx/vdbio/MaskDilation.h>

#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/Morphology.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

using namespace ghostfx;

namespace {

openvdb::MaskTree scatteredVoxels()
{
    openvdb::MaskTree mask;
    sph::Rng rng(2718);
    for (int n = 0; n < 400; ++n) {
        const openvdb::Coord c(int(std::floor(rng.uniform(-40.0f, 40.0f))),
                               int(std::floor(rng.uniform(-40.0f, 40.0f))),
                               int(std::floor(rng.uniform(-40.0f, 40.0f))));
        mask.setValueOn(c);
    }
    return mask;
}

openvdb::MaskTree sphericalShell()
{
    openvdb::MaskTree mask;
    openvdb::Coord c;
    for (c.x() = -30; c.x() <= 30; ++c.x()) {
        for (c.y() = -30; c.y() <= 30; ++c.y()) {
            for (c.z() = -30; c.z() <= 30; ++c.z()) {
                const double r = c.asVec3d().length();
                if (r > 24.0 && r < 27.0) mask.setValueOn(c);
            }
        }
    }
    return mask;
}

/// Active voxels in exactly one of a and b.
openvdb::Index64 symmetricDifference(const openvdb::MaskTree& a, const openvdb::MaskTree& b)
{
    openvdb::MaskTree onlyA(a), onlyB(b);
    onlyA.topologyDifference(b);
    onlyB.topologyDifference(a);
    return onlyA.activeVoxelCount() + onlyB.activeVoxelCount();
}

void expectSameAsOpenVdb(const openvdb::MaskTree& input, const char* name)
{
    for (int k : {1, 2, 3, 5, 7, 8, 9, 13}) {
        openvdb::MaskTree reference(input), ours(input);
        openvdb::tools::dilateActiveValues(reference, k, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::IGNORE_TILES);
        vdbio::dilateMaxNorm(ours, k);
        const openvdb::Index64 differ = symmetricDifference(reference, ours);
        std::printf("[measured] %s, k = %d: %llu voxels, %llu differ\n", name, k,
                    static_cast<unsigned long long>(ours.activeVoxelCount()),
                    static_cast<unsigned long long>(differ));
        EXPECT_EQ(ours.activeVoxelCount(), reference.activeVoxelCount()) << name << " k " << k;
        EXPECT_EQ(differ, 0u) << name << " k " << k;
    }
}

} // namespace

TEST(MaskDilation, ScatteredVoxelsGrowAsOpenVdbsIterations)
{
    expectSameAsOpenVdb(scatteredVoxels(), "scattered");
}

TEST(MaskDilation, AShellGrowsAsOpenVdbsIterations)
{
    expectSameAsOpenVdb(sphericalShell(), "shell");
}

TEST(MaskDilation, FaceNeighboursAsOpenVdbsNnFace)
{
    for (const openvdb::MaskTree& input : {scatteredVoxels(), sphericalShell()}) {
        openvdb::MaskTree reference(input), ours(input);
        openvdb::tools::dilateActiveValues(reference, 1, openvdb::tools::NN_FACE,
                                           openvdb::tools::IGNORE_TILES);
        vdbio::dilateFaces(ours);
        EXPECT_EQ(ours.activeVoxelCount(), reference.activeVoxelCount());
        EXPECT_EQ(symmetricDifference(reference, ours), 0u);
    }
    openvdb::MaskTree one;
    one.setValueOn(openvdb::Coord(0, 7, 8)); // on leaf faces in y and z
    vdbio::dilateFaces(one);
    EXPECT_EQ(one.activeVoxelCount(), 7u);
    EXPECT_TRUE(one.isValueOn(openvdb::Coord(0, 8, 8)));
    EXPECT_TRUE(one.isValueOn(openvdb::Coord(0, 7, 7)));
    EXPECT_FALSE(one.isValueOn(openvdb::Coord(1, 8, 8)));
}

TEST(MaskDilation, OneVoxelBecomesACube)
{
    openvdb::MaskTree mask;
    mask.setValueOn(openvdb::Coord(7, 0, -1)); // on leaf faces in x and z
    vdbio::dilateMaxNorm(mask, 4);
    EXPECT_EQ(mask.activeVoxelCount(), 9u * 9u * 9u);
    openvdb::CoordBBox box;
    ASSERT_TRUE(mask.evalActiveVoxelBoundingBox(box));
    EXPECT_EQ(box.min(), openvdb::Coord(3, -4, -5));
    EXPECT_EQ(box.max(), openvdb::Coord(11, 4, 3));
    EXPECT_THROW(vdbio::dilateMaxNorm(mask, -1), openvdb::ValueError);
}

TEST(MaskDilation, ALevelSetsBandGrowsInPlaceAsByTopologyUnion)
{
    // dilateFaces on a float tree (NarrowBandFlow::track's band growth) against the copy it
    // replaces: its topology dilated as a mask, then united into the tree. Same active voxels,
    // same leaves, and every value the same bit for bit (new voxels keep their inactive values;
    // leaves added over a tile take the tile's value, inside -background, outside +background).
    // A sphere about the origin, so the band crosses the signs of every axis (eight upper nodes).
    openvdb::FloatGrid::Ptr sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        3.0f, openvdb::Vec3f(0.1f), 0.1f, 3.0f);
    const openvdb::FloatTree& input = sphere->tree();
    openvdb::FloatTree reference(input), ours(input);
    openvdb::MaskTree band(reference, false, openvdb::TopologyCopy());
    openvdb::tools::dilateActiveValues(band, 1, openvdb::tools::NN_FACE,
                                       openvdb::tools::IGNORE_TILES);
    reference.topologyUnion(band);
    vdbio::dilateFaces(ours);
    EXPECT_GT(ours.activeVoxelCount(), input.activeVoxelCount());
    EXPECT_EQ(ours.activeVoxelCount(), reference.activeVoxelCount());
    EXPECT_EQ(ours.leafCount(), reference.leafCount());
    std::size_t differ = 0, leaves = 0;
    for (auto leaf = reference.cbeginLeaf(); leaf; ++leaf, ++leaves) {
        const openvdb::FloatTree::LeafNodeType* other = ours.probeConstLeaf(leaf->origin());
        ASSERT_NE(other, nullptr) << leaf->origin();
        differ += leaf->getValueMask() != other->getValueMask();
        differ +=
            std::memcmp(leaf->buffer().data(), other->buffer().data(), leaf->SIZE * sizeof(float))
            != 0;
    }
    std::printf("[measured] level-set sphere: %zu leaves, %zu differ\n", leaves, differ);
    EXPECT_EQ(differ, 0u);
}
