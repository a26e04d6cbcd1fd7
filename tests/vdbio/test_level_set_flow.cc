/// @file   test_level_set_flow.cc
/// @brief  NarrowBandFlow (vdbio/LevelSetFlow.h) against OpenVDB's own tools::LevelSetFilter
///         with the same schemes: the grids must come out equal bit for bit, since NarrowBandFlow
///         claims OpenVDB's arithmetic and only changes how the stencils are read.
/// @details The input is a rough level set like the surface's union of spheres: a ball of
///          radius 30 voxels with 40 bumps of radius 3-6 voxels, exact distances to the union
///          in a band of 3 voxels, flood-filled and pruned (so the ball's interior is tiles,
///          which the padded stencils must read through). Both filters then run the surface's
///          recipe (SurfaceGrid.cc): mean-curvature passes, an erosion in half-voxel steps,
///          and a dilation too.
#include <ghostfx/sph/Random.h>
#include <ghostfx/vdbio/LevelSetFlow.h>

#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <tbb/global_control.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

using namespace ghostfx;

namespace {

constexpr double DX = 0.01;     // voxel size (m)
constexpr float HALF_WIDTH = 3; // voxels

struct Ball
{
    openvdb::Vec3d centre; // index space
    double radius;         // voxels
};

/// A bumpy ball: exact signed distances (in m) to a union of balls, in a band of HALF_WIDTH.
openvdb::FloatGrid::Ptr bumpyBall()
{
    std::vector<Ball> balls{{openvdb::Vec3d(0.0), 30.0}};
    sph::Rng rng(4711);
    for (int n = 0; n < 40; ++n) {
        openvdb::Vec3d d(rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f),
                         rng.uniform(-1.0f, 1.0f));
        if (d.length() < 1e-3) continue;
        d.normalize();
        balls.push_back({d * 31.0, double(rng.uniform(3.0f, 6.0f))});
    }
    openvdb::FloatGrid::Ptr grid = openvdb::createLevelSet<openvdb::FloatGrid>(DX, HALF_WIDTH);
    grid->setName("bumpy");
    const float background = grid->background();
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    const int extent = 40;
    openvdb::Coord c;
    for (c.x() = -extent; c.x() <= extent; ++c.x()) {
        for (c.y() = -extent; c.y() <= extent; ++c.y()) {
            for (c.z() = -extent; c.z() <= extent; ++c.z()) {
                double phi = 1e30;
                for (const Ball& b : balls) {
                    phi = std::min(phi, (c.asVec3d() - b.centre).length() - b.radius);
                }
                const float value = float(phi * DX);
                if (std::abs(value) < background) acc.setValue(c, value);
            }
        }
    }
    openvdb::tools::signedFloodFill(grid->tree());
    openvdb::tools::pruneLevelSet(grid->tree());
    return grid;
}

/// The surface's recipe on `filter` (either filter class): 4 curvature passes, an erosion
/// of 3 voxels and a dilation of 1.3 voxels.
template <typename Filter>
void recipe(Filter& filter)
{
    for (int i = 0; i < 4; ++i) filter.meanCurvature();
    filter.offset(float(3 * DX));
    filter.offset(float(-1.3 * DX));
}

/// Number of voxels (active or not, in leaves or tiles) where a and b differ in state or in
/// the bits of their value; tiles and leaves are compared voxel by voxel.
std::size_t differingVoxels(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b)
{
    std::size_t differ = 0;
    openvdb::CoordBBox box = a.evalActiveVoxelBoundingBox();
    box.expand(b.evalActiveVoxelBoundingBox());
    box.expand(int(HALF_WIDTH) + 8);
    openvdb::FloatGrid::ConstAccessor accA = a.getConstAccessor(), accB = b.getConstAccessor();
    for (auto it = box.begin(); it; ++it) {
        float va = 0, vb = 0;
        const bool onA = accA.probeValue(*it, va), onB = accB.probeValue(*it, vb);
        if (onA != onB || std::memcmp(&va, &vb, sizeof(float)) != 0) ++differ;
    }
    return differ;
}

} // namespace

TEST(LevelSetFlow, EqualsOpenVdbsLevelSetFilterBitForBit)
{
    const openvdb::FloatGrid::Ptr input = bumpyBall();
    // The ball's interior is tiles: the padded stencils next to it read a tile, not a leaf.
    ASSERT_EQ(input->tree().probeConstLeaf(openvdb::Coord(0)), nullptr);
    ASSERT_EQ(input->tree().getValue(openvdb::Coord(0)), -input->background());
    for (int sweeps : {1, 2}) {
        openvdb::FloatGrid::Ptr reference = input->deepCopy();
        openvdb::tools::LevelSetFilter<openvdb::FloatGrid> openvdbFilter(*reference);
        openvdbFilter.setSpatialScheme(openvdb::math::FIRST_BIAS);
        openvdbFilter.setTemporalScheme(openvdb::math::TVD_RK1);
        openvdbFilter.setNormCount(sweeps);
        recipe(openvdbFilter);

        openvdb::FloatGrid::Ptr ours = input->deepCopy();
        vdbio::NarrowBandFlow flow(*ours, sweeps);
        recipe(flow);

        std::printf("[measured] sweeps %d: %llu active voxels (input %llu), %zu differ\n", sweeps,
                    static_cast<unsigned long long>(ours->activeVoxelCount()),
                    static_cast<unsigned long long>(input->activeVoxelCount()),
                    differingVoxels(*reference, *ours));
        EXPECT_EQ(ours->activeVoxelCount(), reference->activeVoxelCount());
        EXPECT_EQ(ours->tree().leafCount(), reference->tree().leafCount());
        EXPECT_EQ(differingVoxels(*reference, *ours), 0u) << "sweeps " << sweeps;
    }
}

TEST(LevelSetFlow, ResultDoesNotDependOnTheThreadCount)
{
    const openvdb::FloatGrid::Ptr input = bumpyBall();
    openvdb::FloatGrid::Ptr one = input->deepCopy(), two = input->deepCopy();
    {
        tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
        vdbio::NarrowBandFlow flow(*one);
        recipe(flow);
    }
    {
        tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
        vdbio::NarrowBandFlow flow(*two);
        recipe(flow);
    }
    EXPECT_EQ(differingVoxels(*one, *two), 0u);
}

TEST(LevelSetFlow, RefusesAGridThatIsNotALevelSet)
{
    openvdb::FloatGrid fog(0.0f);
    fog.setName("density");
    fog.setGridClass(openvdb::GRID_FOG_VOLUME);
    try {
        vdbio::NarrowBandFlow flow(fog);
        FAIL() << "a fog volume was accepted";
    } catch (const openvdb::ValueError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("'density'"), std::string::npos) << what;
        EXPECT_NE(what.find("fog volume"), std::string::npos) << what;
        EXPECT_NE(what.find("expected a level set"), std::string::npos) << what;
    }
    openvdb::FloatGrid::Ptr ball = bumpyBall();
    EXPECT_THROW(vdbio::NarrowBandFlow(*ball, 0), openvdb::ValueError);
}
