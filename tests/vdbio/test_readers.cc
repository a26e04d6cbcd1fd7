/// @file   test_readers.cc
/// @brief  The .vdb readers (Readers.h) against the grids and particles written: every point
///         attribute whatever its type and codec, dense and active-voxel volumes, and the error
///         lines for a missing file, a missing grid and a grid of the wrong kind.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/Info.h>
#include <ghostfx/vdbio/Readers.h>

#include <openvdb/io/File.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointGroup.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "common/Expect.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace ghostfx;
using ghostfx::testing::errorOf;
using ghostfx::testing::freshDir;
using openvdb::points::PointDataGrid;

namespace {

/// 1000 particles on a jittered 10^3 lattice 13 mm apart (jitter from the index, so the test
/// needs no random numbers), with a float and a vector channel besides the built-ins.
sph::ParticleSet latticeParticles()
{
    std::vector<sph::Vec3> x;
    for (int i = 0; i < 1000; ++i) {
        const double j = 0.003 * std::sin(1.7 * i);
        x.emplace_back(sph::Real(0.013 * (i % 10) + j), sph::Real(0.013 * ((i / 10) % 10) - j),
                       sph::Real(0.013 * (i / 100) + 0.5 * j));
    }
    sph::ParticleSet p;
    p.addBatch(x, sph::Real(2e-3), sph::ParticleKind::Liquid);
    std::vector<sph::Real>& temperature = p.addScalarChannel("temperature");
    std::vector<sph::Vec3>& vorticity = p.addVectorChannel("vorticity");
    for (std::size_t i = 0; i < p.size(); ++i) {
        p.velocities()[i] = sph::Vec3(sph::Real(0.01 * i), sph::Real(-0.02 * i), sph::Real(0.5));
        p.densities()[i] = sph::Real(1000 + 0.1 * i);
        temperature[i] = sph::Real(300 + i);
        vorticity[i] = sph::Vec3(sph::Real(i), 0, sph::Real(-1.0 * i));
    }
    return p;
}

/// Attributes of other types and codecs than ghostfx writes, each a function of the point's
/// id so the read-back can be checked row by row: double, int16, bool, vec3d, a float stored
/// as half (truncate codec) and a group "even".
void addForeignAttributes(PointDataGrid& grid)
{
    using namespace openvdb::points;
    auto& tree = grid.tree();
    appendAttribute<double>(tree, "d");
    appendAttribute<std::int16_t>(tree, "s16");
    appendAttribute<bool>(tree, "flag");
    appendAttribute<openvdb::Vec3d>(tree, "w");
    appendAttribute<float, TruncateCodec>(tree, "half");
    appendGroup(tree, "even");
    for (auto leaf = tree.beginLeaf(); leaf; ++leaf) {
        AttributeHandle<std::int64_t> id(leaf->constAttributeArray("id"));
        AttributeWriteHandle<double> d(leaf->attributeArray("d"));
        AttributeWriteHandle<std::int16_t> s16(leaf->attributeArray("s16"));
        AttributeWriteHandle<bool> flag(leaf->attributeArray("flag"));
        AttributeWriteHandle<openvdb::Vec3d> w(leaf->attributeArray("w"));
        AttributeWriteHandle<float> half(leaf->attributeArray("half"));
        GroupWriteHandle even = leaf->groupWriteHandle("even");
        for (openvdb::Index n = 0; n < leaf->pointCount(); ++n) {
            const std::int64_t i = id.get(n);
            d.set(n, 0.5 * double(i) + 1e-10);
            s16.set(n, std::int16_t(-i));
            flag.set(n, i % 3 == 0);
            w.set(n, openvdb::Vec3d(1e-12 * double(i), 1.0, double(i)));
            half.set(n, float(i)); // integers up to 2048 are exact in half precision
            even.set(n, i % 2 == 0);
        }
    }
}

const vdbio::Column& columnNamed(const vdbio::PointsData& data, const std::string& name)
{
    for (const vdbio::Column& c : data.columns) {
        if (c.name == name) return c;
    }
    ADD_FAILURE() << "no column '" << name << "'";
    return data.columns.front();
}

} // namespace

TEST(Readers, PointsComeBackWithEveryAttributeInItsStoredType)
{
    const fs::path dir = freshDir("readers_points");
    const sph::ParticleSet particles = latticeParticles();
    vdbio::PointsOptions options;
    options.channels = {"v", "id", "density", "kind", "temperature", "vorticity"};
    const std::string file = (dir / "points.vdb").string();
    vdbio::writePointsFile(file, particles, options);

    const vdbio::PointsData data = vdbio::readPoints(file, "", "test");
    ASSERT_EQ(data.count, particles.size());
    EXPECT_EQ(data.grid, "particles");
    std::vector<std::string> names;
    for (const vdbio::Column& c : data.columns) {
        EXPECT_EQ(c.rows, data.count) << c.name;
        names.push_back(c.name);
    }
    EXPECT_EQ(names, (std::vector<std::string>{"P", "v", "id", "density", "kind", "temperature",
                                               "vorticity"}));
    const vdbio::Column& P = columnNamed(data, "P");
    const vdbio::Column& id = columnNamed(data, "id");
    EXPECT_EQ(P.scalar, vdbio::ScalarType::Float64);
    EXPECT_EQ(P.storedType, "vec3s (null)");
    EXPECT_EQ(id.scalar, vdbio::ScalarType::Int64);
    EXPECT_EQ(columnNamed(data, "v").scalar, vdbio::ScalarType::Float32);
    EXPECT_EQ(columnNamed(data, "kind").scalar, vdbio::ScalarType::Int32);

    // P is stored as a float offset in [-0.5, 0.5] voxel from the voxel centre: its rounding is
    // at most half a float ulp of 0.5, 2^-25 voxel; the bound allows twice that.
    const double tolerance = data.voxelSize * std::ldexp(1.0, -24);
    double worst = 0;
    std::vector<int> seen(particles.size(), 0);
    for (std::size_t r = 0; r < data.count; ++r) {
        const std::size_t i = std::size_t(id.data<std::int64_t>()[r]);
        ASSERT_LT(i, particles.size());
        ++seen[i];
        for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(P.value(r, c) - double(particles.positions()[i][c])));
            // Float channels are stored as float: exact.
            EXPECT_EQ(columnNamed(data, "v").value(r, c), double(float(particles.velocities()[i][c])));
            EXPECT_EQ(columnNamed(data, "vorticity").value(r, c),
                      double(float(particles.vectorChannel("vorticity")[i][c])));
        }
        EXPECT_EQ(columnNamed(data, "density").value(r, 0), double(float(particles.densities()[i])));
        EXPECT_EQ(columnNamed(data, "temperature").value(r, 0),
                  double(float(particles.scalarChannel("temperature")[i])));
        EXPECT_EQ(columnNamed(data, "kind").value(r, 0), double(sph::ParticleKind::Liquid));
    }
    std::printf("[measured] %zu points, voxel %.4g m, worst |P - x| = %.3g m (bound %.3g m)\n",
                data.count, data.voxelSize, worst, tolerance);
    EXPECT_LE(worst, tolerance);
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(particles.size()));
}

namespace {

/// The lattice's points as writePointsFile writes them into `dir`, read back as a grid to
/// change.
PointDataGrid::Ptr writtenLatticeGrid(const fs::path& dir)
{
    const std::string written = (dir / "points.vdb").string();
    vdbio::writePointsFile(written, latticeParticles(), vdbio::PointsOptions());
    openvdb::io::File in(written);
    in.open();
    const PointDataGrid::Ptr grid = openvdb::gridPtrCast<PointDataGrid>(in.readGrid("particles"));
    in.close();
    return grid;
}

} // namespace

TEST(Readers, PointAttributesOfOtherTypesCodecsAndGroups)
{
    const fs::path dir = freshDir("readers_foreign");
    const PointDataGrid::Ptr grid = writtenLatticeGrid(dir);
    addForeignAttributes(*grid);
    grid->setName("spray");
    const std::string file = (dir / "foreign.vdb").string();
    openvdb::io::File(file).write({grid});

    const vdbio::PointsData data = vdbio::readPoints(file, "spray", "test");
    const vdbio::Column& id = columnNamed(data, "id");
    EXPECT_EQ(columnNamed(data, "d").scalar, vdbio::ScalarType::Float64);
    EXPECT_EQ(columnNamed(data, "s16").scalar, vdbio::ScalarType::Int16);
    EXPECT_EQ(columnNamed(data, "flag").scalar, vdbio::ScalarType::Bool);
    EXPECT_EQ(columnNamed(data, "w").components, 3);
    EXPECT_EQ(columnNamed(data, "half").storedType, "float (trnc)");
    for (std::size_t r = 0; r < data.count; ++r) {
        const double i = double(id.data<std::int64_t>()[r]);
        EXPECT_EQ(columnNamed(data, "d").value(r, 0), 0.5 * i + 1e-10); // double: exact
        EXPECT_EQ(columnNamed(data, "s16").value(r, 0), -i);
        EXPECT_EQ(columnNamed(data, "flag").value(r, 0), std::fmod(i, 3) == 0 ? 1 : 0);
        EXPECT_EQ(columnNamed(data, "w").value(r, 0), 1e-12 * i);
        EXPECT_EQ(columnNamed(data, "w").value(r, 2), i);
        EXPECT_EQ(columnNamed(data, "half").value(r, 0), i);
        EXPECT_EQ(columnNamed(data, "group:even").value(r, 0), std::fmod(i, 2) == 0 ? 1 : 0);
    }
    const vdbio::ColumnRange range = vdbio::columnRange(columnNamed(data, "s16"));
    EXPECT_EQ(range.min[0], -999);
    EXPECT_EQ(range.max[0], 0);
    EXPECT_DOUBLE_EQ(range.mean[0], -499.5); // ids 0..999
}

namespace {

/// A file with a level set "surface" (sphere of radius 0.1 m, 5 mm voxels, centred off the
/// origin), its fog volume "density" (active tiles inside), a vec3s "vel" and a point grid.
/// (OpenVDB lists a file's grids by name: density, particles, surface, vel.)
std::string volumeFile(const fs::path& dir)
{
    auto surface = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        0.1f, openvdb::Vec3f(0.3f, 0.2f, -0.1f), 0.005f);
    surface->setName("surface");
    auto density = surface->deepCopy();
    openvdb::tools::sdfToFogVolume(*density);
    density->setName("density");
    auto vel = openvdb::Vec3SGrid::create(openvdb::Vec3s(0));
    vel->setTransform(surface->transform().copy());
    vel->setName("vel");
    for (int i = -3; i <= 3; ++i) vel->tree().setValue(openvdb::Coord(i, 2 * i, 7), openvdb::Vec3s(float(i), 1, -2));
    const std::string points = (dir / "p.vdb").string();
    vdbio::writePointsFile(points, latticeParticles(), vdbio::PointsOptions());
    openvdb::io::File in(points);
    in.open();
    const openvdb::GridBase::Ptr particles = in.readGrid("particles");
    in.close();
    const std::string file = (dir / "frame.vdb").string();
    openvdb::io::File(file).write({surface, density, vel, particles});
    return file;
}

} // namespace

TEST(Readers, DenseVolumeHoldsTheGridsValuesOverItsActiveBox)
{
    const fs::path dir = freshDir("readers_dense");
    const std::string file = volumeFile(dir);
    openvdb::io::File in(file);
    in.open();
    const auto surface = openvdb::gridPtrCast<openvdb::FloatGrid>(in.readGrid("surface"));
    in.close();

    const vdbio::DenseVolume dense = vdbio::readDenseVolume(file, "surface", "test");
    const openvdb::CoordBBox box = surface->evalActiveVoxelBoundingBox();
    EXPECT_EQ(dense.header.gridClass, "level set");
    EXPECT_EQ(dense.header.valueType, "float");
    EXPECT_EQ(dense.header.voxelSize[0], 0.005f);
    EXPECT_EQ(dense.header.background.value(0, 0), surface->background());
    EXPECT_EQ(dense.indexMin[0], box.min().x());
    EXPECT_EQ(dense.dims[2], box.dim().z());
    const openvdb::Vec3d origin = surface->indexToWorld(box.min());
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(dense.origin[std::size_t(c)], origin[c]);
        // Row 3 of the 4x4 is the translation: world of index (0, 0, 0).
        EXPECT_EQ(dense.header.indexToWorld[std::size_t(12 + c)], surface->indexToWorld(openvdb::Coord(0))[c]);
    }
    const auto acc = surface->getConstAccessor();
    std::size_t mismatches = 0, row = 0;
    for (int i = 0; i < dense.dims[0]; ++i) {
        for (int j = 0; j < dense.dims[1]; ++j) {
            for (int k = 0; k < dense.dims[2]; ++k, ++row) {
                const float v = acc.getValue(box.min() + openvdb::Coord(i, j, k));
                mismatches += dense.values.data<float>()[row] != v;
            }
        }
    }
    EXPECT_EQ(row, dense.values.rows);
    EXPECT_EQ(mismatches, 0u); // the same floats, copied

    const vdbio::DenseVolume vel = vdbio::readDenseVolume(file, "vel", "test");
    EXPECT_EQ(vel.values.components, 3);
    EXPECT_EQ((vel.dims), (std::array<int, 3>{7, 13, 1}));
    // values[i][j][k] at index (-3 + i, -6 + j, 7): (3, 6, 0) is voxel (0, 0, 7), value (0, 1, -2).
    const std::size_t r = (3u * 13u + 6u) * 1u;
    EXPECT_EQ(vel.values.value(r, 0), 0.0);
    EXPECT_EQ(vel.values.value(r, 1), 1.0);
    EXPECT_EQ(vel.values.value(r, 2), -2.0);
}

TEST(Readers, ActiveVoxelsExpandTilesAndGiveWorldPositions)
{
    const fs::path dir = freshDir("readers_active");
    const std::string file = volumeFile(dir);
    openvdb::io::File in(file);
    in.open();
    const auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(in.readGrid("density"));
    in.close();
    ASSERT_GT(density->tree().activeTileCount(), 0u); // the fog's inside is tiles

    const vdbio::ActiveVoxels active = vdbio::readActiveVoxels(file, "density", "test");
    EXPECT_EQ(active.header.gridClass, "fog volume");
    ASSERT_EQ(active.ijk.size(), std::size_t(density->activeVoxelCount()));
    ASSERT_EQ(active.values.rows, active.ijk.size());
    const auto acc = density->getConstAccessor();
    std::size_t mismatches = 0;
    for (std::size_t r = 0; r < active.ijk.size(); ++r) {
        const openvdb::Coord ijk(active.ijk[r][0], active.ijk[r][1], active.ijk[r][2]);
        const openvdb::Vec3d w = density->indexToWorld(ijk);
        mismatches += !acc.isValueOn(ijk) || acc.getValue(ijk) != active.values.data<float>()[r]
                      || w.x() != active.world[r][0] || w.z() != active.world[r][2];
    }
    EXPECT_EQ(mismatches, 0u);
}

TEST(Readers, ErrorsNameTheFileAndTheGrid)
{
    const fs::path dir = freshDir("readers_errors");
    const std::string file = volumeFile(dir);
    const std::string missing = (dir / "missing.vdb").string();
    EXPECT_EQ(errorOf<IoError>([&] { vdbio::readPoints(missing, "", "read_points"); }),
              "read_points: file '" + missing + "' does not exist");
    EXPECT_EQ(errorOf<GridError>([&] { vdbio::readPoints(file, "spray", "read_points"); }),
              "read_points: file '" + file
                  + "' has no grid 'spray' (grids: 'density' (float), 'particles' (ptdataidx32), "
                    "'surface' (float), 'vel' (vec3s))");
    EXPECT_EQ(errorOf<GridError>([&] { vdbio::readPoints(file, "surface", "read_points"); }),
              "read_points: grid 'surface' in '" + file
                  + "' holds float values, expected a point grid (PointDataGrid)");
    EXPECT_EQ(errorOf<GridError>([&] { vdbio::readDenseVolume(file, "particles", "read_volume"); }),
              "read_volume: grid 'particles' in '" + file
                  + "' is a point grid, expected a volume (read its points instead)");
    EXPECT_EQ(errorOf<GridError>([&] { vdbio::readActiveVoxels(file, "rho", "read_volume"); }),
              "read_volume: file '" + file
                  + "' has no grid 'rho' (grids: 'density' (float), 'particles' (ptdataidx32), "
                    "'surface' (float), 'vel' (vec3s))");

    const std::string volumesOnly = (dir / "volumes.vdb").string();
    openvdb::io::File(volumesOnly).write({openvdb::FloatGrid::create()});
    EXPECT_EQ(errorOf<GridError>([&] { vdbio::readPoints(volumesOnly, "", "read_points"); }),
              "read_points: file '" + volumesOnly + "' has no point grid (grids: '' (float))");
    const std::string text = (dir / "notes.vdb").string();
    std::ofstream(text) << "hello\n";
    EXPECT_TRUE(ghostfx::testing::contains(errorOf<IoError>([&] { vdbio::readPoints(text, "", "read_points"); }),
                                  "read_points: file '" + text + "' is not a readable .vdb file ("));
}

TEST(Readers, AnAttributeOfAnotherTypeIsNamedAndInfoStillDescribesTheFile)
{
    const fs::path dir = freshDir("readers_unsupported");
    const PointDataGrid::Ptr grid = writtenLatticeGrid(dir);
    openvdb::points::appendAttribute<openvdb::math::Mat4s>(grid->tree(), "xform");
    const std::string file = (dir / "matrices.vdb").string();
    openvdb::io::File(file).write({grid});
    const std::string expected =
        "attribute 'xform' of point grid 'particles' holds mat4s values, expected float, double, "
        "int8 to int64, uint8 to uint64, bool, vec3s, vec3d or vec3i";
    EXPECT_EQ(errorOf<GridError>([&] { vdbio::readPoints(file, "", "read_points"); }),
              "read_points: '" + file + "': " + expected);
    const std::string info = vdbio::describeFile(file);
    EXPECT_TRUE(ghostfx::testing::contains(
        info, "  attribute ranges: not read (ghostfx info: " + expected + ")\n"))
        << info;
    EXPECT_TRUE(ghostfx::testing::contains(info, "points:          1000\n")) << info;

    // A grid without points: an empty P, (0, 3).
    const std::string empty = (dir / "empty.vdb").string();
    vdbio::writePointsFile(empty, sph::ParticleSet(), vdbio::PointsOptions());
    const vdbio::PointsData none = vdbio::readPoints(empty, "particles", "read_points");
    ASSERT_EQ(none.columns.size(), 1u);
    EXPECT_EQ(none.columns[0].name, "P");
    EXPECT_EQ(none.columns[0].rows, 0u);
    EXPECT_EQ(none.columns[0].components, 3);
}
