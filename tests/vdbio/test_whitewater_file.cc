/// @file   test_whitewater_file.cc
/// @brief  Whitewater files read back: points round trip by id, attribute types, fog volume
///         conservation and clamping, one class per fog grid, independence of the particles'
///         order, empty input and error messages.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Random.h>
#include <ghostfx/vdbio/Readers.h>
#include <ghostfx/vdbio/WhitewaterFile.h>

#include <openvdb/io/File.h>

#include "common/Expect.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>

namespace fs = std::filesystem;
using namespace ghostfx;
using ghostfx::testing::contains;
using ghostfx::testing::errorOf;
using ghostfx::testing::freshDir;

namespace {

constexpr double PSCALE = 0.01; // particle radius (m)
const double PARTICLE_VOLUME =
    4.0 / 3.0 * openvdb::math::pi<double>() * PSCALE * PSCALE * PSCALE; // m^3

/// `n` particles uniform in the cube [0, side)^3 (m), velocities in [-3, 3) m/s, ids
/// 1000 + 7 k, classes cycling spray, foam, bubble, ages in [0, 3) s.
vdbio::WhitewaterPoints randomPoints(std::size_t n, double side, std::uint64_t seed)
{
    sph::Rng rng(seed);
    vdbio::WhitewaterPoints p;
    for (std::size_t k = 0; k < n; ++k) {
        p.positions.emplace_back(rng.uniform(0, sph::Real(side)), rng.uniform(0, sph::Real(side)),
                                 rng.uniform(0, sph::Real(side)));
        p.velocities.emplace_back(rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3));
        p.ids.push_back(std::int64_t(1000 + 7 * k));
        p.types.push_back(std::int32_t(k % 3));
        p.ages.push_back(float(3.0 * rng.uniform01()));
    }
    return p;
}

/// `p` with its particles in a random order (Fisher-Yates).
vdbio::WhitewaterPoints shuffled(const vdbio::WhitewaterPoints& p, std::uint64_t seed)
{
    std::vector<std::size_t> order(p.positions.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    sph::Rng rng(seed);
    for (std::size_t k = order.size(); k > 1; --k)
        std::swap(order[k - 1], order[rng.below(std::uint32_t(k))]);
    vdbio::WhitewaterPoints out;
    for (std::size_t k : order) {
        out.positions.push_back(p.positions[k]);
        out.velocities.push_back(p.velocities[k]);
        out.ids.push_back(p.ids[k]);
        out.types.push_back(p.types[k]);
        out.ages.push_back(p.ages[k]);
    }
    return out;
}

const vdbio::Column& columnNamed(const vdbio::PointsData& data, const std::string& name)
{
    for (const vdbio::Column& c : data.columns) {
        if (c.name == name) return c;
    }
    ADD_FAILURE() << "no column '" << name << "'";
    return data.columns.front();
}

/// The grid names of `file` (io::File lists them sorted).
std::set<std::string> gridNames(const std::string& file)
{
    openvdb::io::File f(file);
    f.open();
    std::set<std::string> names;
    for (auto it = f.beginName(); it != f.endName(); ++it) names.insert(it.gridName());
    return names;
}

/// Sum over the active voxels of `grid` in `file` of value x voxel volume (m^3).
double fogVolume(const std::string& file, const std::string& grid)
{
    const vdbio::ActiveVoxels fog = vdbio::readActiveVoxels(file, grid, "test");
    const double dx = fog.header.voxelSize[0];
    double sum = 0;
    for (std::size_t r = 0; r < fog.values.rows; ++r) sum += fog.values.value(r, 0);
    return sum * dx * dx * dx;
}

std::size_t activeVoxels(const std::string& file, const std::string& grid)
{
    return vdbio::readActiveVoxels(file, grid, "test").ijk.size();
}

} // namespace

TEST(WhitewaterFile, PointsComeBackByIdWithTheirAttributeTypes)
{
    const fs::path dir = freshDir("whitewater_round_trip");
    const vdbio::WhitewaterPoints points = randomPoints(1000, 1.0, 1);
    vdbio::WhitewaterGridOptions options;
    options.pscale = PSCALE;
    options.fogVoxelSize = 0.05;
    openvdb::MetaMap meta;
    meta.insertMeta("frame", openvdb::Int32Metadata(7));
    const std::string file = (dir / "ww.vdb").string();
    vdbio::writeWhitewaterFile(file, vdbio::makeWhitewaterGrids(points, options), meta);

    EXPECT_EQ(gridNames(file), (std::set<std::string>{"whitewater", "spray", "foam", "bubbles"}));
    openvdb::io::File f(file);
    f.open();
    EXPECT_EQ(f.getMetadata()->metaValue<std::int32_t>("frame"), 7);

    const vdbio::PointsData data = vdbio::readPoints(file, "whitewater", "test");
    ASSERT_EQ(data.count, points.positions.size());
    const vdbio::Column& P = columnNamed(data, "P");
    const vdbio::Column& v = columnNamed(data, "v");
    const vdbio::Column& id = columnNamed(data, "id");
    const vdbio::Column& type = columnNamed(data, "type");
    const vdbio::Column& age = columnNamed(data, "age");
    const vdbio::Column& pscale = columnNamed(data, "pscale");
    EXPECT_EQ(P.storedType, "vec3s (null)");
    EXPECT_EQ(v.storedType, "vec3s (null)");
    EXPECT_EQ(id.scalar, vdbio::ScalarType::Int64);
    EXPECT_EQ(type.scalar, vdbio::ScalarType::Int32);
    EXPECT_EQ(age.scalar, vdbio::ScalarType::Float32);
    EXPECT_EQ(pscale.scalar, vdbio::ScalarType::Float32);
    EXPECT_EQ(pscale.components, 1);

    std::map<std::int64_t, std::size_t> byId;
    for (std::size_t k = 0; k < points.ids.size(); ++k) byId[points.ids[k]] = k;
    // P is a float offset of at most half a voxel from the voxel centre: its rounding is at
    // most half a float ulp of 0.5 voxel, 2^-25 voxel; the bound allows twice that (about
    // 1e-8 m at this voxel size, well inside the 1e-6 m a 1 um sim cache keeps).
    const double tolerance = data.voxelSize * std::ldexp(1.0, -24);
    std::set<std::int64_t> seen;
    for (std::size_t r = 0; r < data.count; ++r) {
        const std::int64_t i = id.data<std::int64_t>()[r];
        ASSERT_EQ(byId.count(i), 1u) << "unknown id " << i;
        EXPECT_TRUE(seen.insert(i).second) << "id " << i << " twice";
        const std::size_t k = byId[i];
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(P.value(r, c), double(points.positions[k][c]), tolerance);
            EXPECT_EQ(v.value(r, c), double(float(points.velocities[k][c]))); // stored as float
        }
        EXPECT_EQ(type.value(r, 0), double(points.types[k]));
        EXPECT_EQ(age.value(r, 0), double(points.ages[k]));
        EXPECT_EQ(pscale.value(r, 0), double(float(PSCALE)));
    }
}

TEST(WhitewaterFog, VolumeOfSeparateParticlesIsKeptPerClass)
{
    // Particles 4 voxels apart on a lattice, each jittered inside its cell: no voxel receives
    // two particles, and pscale = 0.4 dx puts at most 4/3 pi 0.4^3 = 0.27 into one voxel, so
    // nothing clamps and the trilinear weights, which sum to one, keep each particle's volume.
    const double dx = PSCALE / 0.4;
    sph::Rng rng(2);
    vdbio::WhitewaterPoints points;
    std::size_t count[3] = {0, 0, 0};
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            for (int k = 0; k < 6; ++k) {
                const int t = (i + j + k) % 3;
                const auto at = [&](int n) { return sph::Real((4 * n + rng.uniform01()) * dx); };
                points.positions.emplace_back(at(i), at(j), at(k));
                points.velocities.emplace_back(0, 0, 0);
                points.ids.push_back(std::int64_t(points.ids.size()));
                points.types.push_back(t);
                points.ages.push_back(0.f);
                ++count[t];
            }
    vdbio::WhitewaterGridOptions options;
    options.pscale = PSCALE;
    options.fogVoxelSize = dx;
    const fs::path dir = freshDir("whitewater_fog_volume");
    const std::string file = (dir / "ww.vdb").string();
    vdbio::writeWhitewaterFile(file, vdbio::makeWhitewaterGrids(points, options));

    for (int t = 0; t < 3; ++t) {
        const std::string name = vdbio::WHITEWATER_FOG_NAMES[t];
        const vdbio::ActiveVoxels fog = vdbio::readActiveVoxels(file, name, "test");
        EXPECT_EQ(fog.header.gridClass, "fog volume");
        EXPECT_DOUBLE_EQ(fog.header.voxelSize[0], dx);
        // Each voxel value is rounded to float (relative 6e-8) and the sum runs over a few
        // hundred of them: 1e-5 relative leaves two orders of magnitude.
        EXPECT_NEAR(fogVolume(file, name), double(count[t]) * PARTICLE_VOLUME,
                    1e-5 * double(count[t]) * PARTICLE_VOLUME)
            << name;
        // Each particle lands on at most 8 voxels, none shared.
        EXPECT_LE(fog.ijk.size(), 8 * count[t]);
        EXPECT_GT(fog.ijk.size(), count[t]);
    }
}

TEST(WhitewaterFog, CrowdedVoxelClampsToOne)
{
    // 50 particles exactly on one voxel centre (dx a power of two: exact positions) each add
    // 4/3 pi (pscale/dx)^3 = 4.2 to that voxel alone (the other 7 weights are exactly 0).
    const double dx = 0.125;
    vdbio::WhitewaterPoints points;
    for (int k = 0; k < 50; ++k) {
        points.positions.emplace_back(sph::Real(3 * dx), sph::Real(-2 * dx), sph::Real(5 * dx));
        points.velocities.emplace_back(0, 0, 0);
        points.ids.push_back(k);
        points.types.push_back(2);
        points.ages.push_back(0.f);
    }
    const openvdb::FloatGrid::Ptr fog = vdbio::makeWhitewaterFog(points, -1, dx, dx, "all");
    EXPECT_EQ(fog->activeVoxelCount(), 1u);
    EXPECT_EQ(fog->tree().getValue(openvdb::Coord(3, -2, 5)), 1.0f);
    EXPECT_EQ(fog->getName(), "all");
    EXPECT_EQ(fog->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(fog->background(), 0.0f);
    // Of one class only: spray has none of these bubbles.
    EXPECT_EQ(vdbio::makeWhitewaterFog(points, 0, dx, dx, "spray")->activeVoxelCount(), 0u);
}

TEST(WhitewaterFog, FoamAppearsOnlyInTheFoamGrid)
{
    vdbio::WhitewaterPoints points = randomPoints(200, 0.5, 3);
    for (std::int32_t& t : points.types) t = 1;
    vdbio::WhitewaterGridOptions options;
    options.pscale = PSCALE;
    options.fogVoxelSize = 0.02;
    const fs::path dir = freshDir("whitewater_foam_only");
    const std::string file = (dir / "ww.vdb").string();
    vdbio::writeWhitewaterFile(file, vdbio::makeWhitewaterGrids(points, options));
    EXPECT_EQ(activeVoxels(file, "spray"), 0u);
    EXPECT_EQ(activeVoxels(file, "bubbles"), 0u);
    EXPECT_GT(activeVoxels(file, "foam"), 200u);
}

TEST(WhitewaterFile, NoFogVoxelSizeWritesOnlyThePoints)
{
    vdbio::WhitewaterGridOptions options;
    options.pscale = PSCALE;
    const fs::path dir = freshDir("whitewater_no_fog");
    const std::string file = (dir / "ww.vdb").string();
    vdbio::writeWhitewaterFile(file,
                               vdbio::makeWhitewaterGrids(randomPoints(100, 1.0, 4), options));
    EXPECT_EQ(gridNames(file), std::set<std::string>{"whitewater"});
}

TEST(WhitewaterFog, ShuffledInputGivesIdenticalGrids)
{
    // Dense enough that most voxels sum several particles (and some clamp): the sums must not
    // depend on the order the particles come in, to the last bit.
    const vdbio::WhitewaterPoints points = randomPoints(3000, 0.2, 5);
    const vdbio::WhitewaterPoints other = shuffled(points, 6);
    vdbio::WhitewaterGridOptions options;
    options.pscale = PSCALE;
    options.fogVoxelSize = 0.02;
    const openvdb::GridPtrVec a = vdbio::makeWhitewaterGrids(points, options);
    const openvdb::GridPtrVec b = vdbio::makeWhitewaterGrids(other, options);
    ASSERT_EQ(a.size(), 4u);
    ASSERT_EQ(b.size(), 4u);
    for (std::size_t g = 1; g < 4; ++g) {
        const auto& fa = static_cast<const openvdb::FloatGrid&>(*a[g]);
        const auto& fb = static_cast<const openvdb::FloatGrid&>(*b[g]);
        EXPECT_EQ(fa.activeVoxelCount(), fb.activeVoxelCount()) << fa.getName();
        EXPECT_GT(fa.activeVoxelCount(), 0u);
        for (auto it = fa.cbeginValueOn(); it; ++it) {
            EXPECT_TRUE(fb.tree().isValueOn(it.getCoord())) << it.getCoord();
            EXPECT_EQ(fb.tree().getValue(it.getCoord()), *it) << it.getCoord();
        }
    }
    // The points: the same values per id (their order inside a voxel follows the input).
    const vdbio::PointsData pa = vdbio::readPointsGrid(*a[0], "test");
    const vdbio::PointsData pb = vdbio::readPointsGrid(*b[0], "test");
    ASSERT_EQ(pa.count, pb.count);
    std::map<std::int64_t, std::vector<double>> rowsA, rowsB;
    for (auto [data, rows] : {std::pair{&pa, &rowsA}, std::pair{&pb, &rowsB}}) {
        const vdbio::Column& id = columnNamed(*data, "id");
        for (std::size_t r = 0; r < data->count; ++r) {
            std::vector<double>& row = (*rows)[id.data<std::int64_t>()[r]];
            for (const vdbio::Column& c : data->columns)
                for (int d = 0; d < c.components; ++d) row.push_back(c.value(r, d));
        }
    }
    EXPECT_EQ(rowsA, rowsB);
}

TEST(WhitewaterFile, EmptyInputWritesAReadableFile)
{
    vdbio::WhitewaterGridOptions options;
    options.pscale = PSCALE;
    options.fogVoxelSize = 0.05;
    const fs::path dir = freshDir("whitewater_empty");
    const std::string file = (dir / "ww.vdb").string();
    vdbio::writeWhitewaterFile(file, vdbio::makeWhitewaterGrids({}, options));
    const vdbio::PointsData data = vdbio::readPoints(file, "whitewater", "test");
    EXPECT_EQ(data.count, 0u);
    for (const char* name : vdbio::WHITEWATER_FOG_NAMES) EXPECT_EQ(activeVoxels(file, name), 0u);
}

TEST(WhitewaterFile, BadInputIsRefusedInOneLineNamingIt)
{
    vdbio::WhitewaterGridOptions options;
    options.pscale = PSCALE;
    vdbio::WhitewaterPoints points = randomPoints(10, 1.0, 7);
    points.velocities.pop_back();
    std::string e = errorOf<ValueError>([&] { vdbio::makeWhitewaterGrids(points, options); });
    EXPECT_TRUE(contains(e, "positions 10, velocities 9, ids 10, types 10, ages 10")) << e;
    EXPECT_FALSE(contains(e, "\n")) << e;

    points = randomPoints(10, 1.0, 7);
    points.types[4] = 3;
    e = errorOf<ValueError>([&] { vdbio::makeWhitewaterGrids(points, options); });
    EXPECT_TRUE(contains(e, "type 3 of particle 4 (id 1028)")) << e;
    EXPECT_FALSE(contains(e, "\n")) << e;
    e = errorOf<ValueError>([&] { vdbio::makeWhitewaterFog(points, 3, 0.1, PSCALE, "fog"); });
    EXPECT_TRUE(contains(e, "type 3")) << e;

    options.pscale = 0;
    e = errorOf<ValueError>([&] { vdbio::makeWhitewaterGrids(randomPoints(10, 1.0, 7), options); });
    EXPECT_TRUE(contains(e, "pscale = 0 m")) << e;
    options.pscale = PSCALE;
    options.fogVoxelSize = -1;
    e = errorOf<ValueError>([&] { options.validate(); });
    EXPECT_TRUE(contains(e, "fogVoxelSize = -1 m")) << e;

    e = errorOf<IoError>([&] {
        vdbio::writeWhitewaterFile("/nonexistent_ghostfx_folder/ww.vdb", openvdb::GridPtrVec());
    });
    EXPECT_TRUE(contains(e, "'/nonexistent_ghostfx_folder/ww.vdb'")) << e;
}
