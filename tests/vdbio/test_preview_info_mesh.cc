/// @file   test_preview_info_mesh.cc
/// @brief  Mesh to level set (against analytic distances), EXR previews, `info` descriptions.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/Info.h>
#include <ghostfx/vdbio/MeshToSdf.h>
#include <ghostfx/vdbio/Preview.h>

#include <openvdb/io/File.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "common/Expect.h"

#include <gtest/gtest.h>

// The HDF5 part needs the test executable to see HDF5's headers and libraries (HDF5::HDF5 in
// tests/CMakeLists.txt); without them it is skipped with a message.
#if __has_include(<H5Cpp.h>)
#include <H5Cpp.h>
#define GHOSTFX_TEST_HDF5 1
#else
#define GHOSTFX_TEST_HDF5 0
#endif

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace ghostfx;
using openvdb::Vec3d;

namespace {

using ghostfx::testing::freshDir;

void writeText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

using ghostfx::testing::contains;
using ghostfx::testing::errorOf;

/// Axis-aligned box [lo, hi] as an OBJ with one normal per face (so Assimp keeps 24 vertices
/// and the converter must weld them), faces as quads (so Assimp must triangulate).
/// `withTop = false` leaves the +y face out: an open box.
std::string boxObj(const Vec3d& lo, const Vec3d& hi, bool withTop = true)
{
    std::string obj = "# box\n";
    for (int i = 0; i < 8; ++i) {
        obj += "v " + std::to_string((i & 1) ? hi.x() : lo.x()) + " "
               + std::to_string((i & 2) ? hi.y() : lo.y()) + " "
               + std::to_string((i & 4) ? hi.z() : lo.z()) + "\n";
    }
    obj += "vn -1 0 0\nvn 1 0 0\nvn 0 -1 0\nvn 0 1 0\nvn 0 0 -1\nvn 0 0 1\n";
    // Vertex numbers (1-based) of each face, counter-clockwise seen from outside.
    obj += "f 1//1 5//1 7//1 3//1\n";              // -x
    obj += "f 2//2 4//2 8//2 6//2\n";              // +x
    obj += "f 1//3 2//3 6//3 5//3\n";              // -y
    if (withTop) obj += "f 3//4 7//4 8//4 4//4\n"; // +y
    obj += "f 1//5 3//5 4//5 2//5\n";              // -z
    obj += "f 5//6 6//6 8//6 7//6\n";              // +z
    return obj;
}

/// The same box as an ASCII PLY with quad faces.
std::string boxPly(const Vec3d& lo, const Vec3d& hi)
{
    std::string ply = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 6\n"
                      "property list uchar int vertex_indices\nend_header\n";
    for (int i = 0; i < 8; ++i) {
        ply += std::to_string((i & 1) ? hi.x() : lo.x()) + " "
               + std::to_string((i & 2) ? hi.y() : lo.y()) + " "
               + std::to_string((i & 4) ? hi.z() : lo.z()) + "\n";
    }
    ply += "4 0 4 6 2\n4 1 3 7 5\n4 0 1 5 4\n4 2 6 7 3\n4 0 2 3 1\n4 4 5 7 6\n";
    return ply;
}

/// Exact signed distance to the box [lo, hi] (m), negative inside.
double boxDistance(const Vec3d& x, const Vec3d& lo, const Vec3d& hi)
{
    const Vec3d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
    const Vec3d q(std::abs(x.x() - c.x()) - h.x(), std::abs(x.y() - c.y()) - h.y(),
                  std::abs(x.z() - c.z()) - h.z());
    const Vec3d outside(std::max(q.x(), 0.0), std::max(q.y(), 0.0), std::max(q.z(), 0.0));
    return outside.length() + std::min(std::max(q.x(), std::max(q.y(), q.z())), 0.0);
}

/// Largest |phi - exact| (in voxels) at points 0.5 and 1.5 voxels inside and outside of the
/// centre of every face, sampled trilinearly.
double maxFaceErrorVoxels(const openvdb::FloatGrid& grid, const Vec3d& lo, const Vec3d& hi)
{
    const double dx = grid.voxelSize()[0];
    const Vec3d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
    openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(grid);
    double worst = 0;
    for (int axis = 0; axis < 3; ++axis) {
        for (double side : {-1.0, 1.0}) {
            for (double offset : {-1.5, -0.5, 0.5, 1.5}) {
                Vec3d x = c;
                x[axis] += side * (h[axis] + offset * dx);
                const double phi = sampler.wsSample(x);
                worst = std::max(worst, std::abs(phi - boxDistance(x, lo, hi)) / dx);
            }
        }
    }
    return worst;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// mesh2sdf
// ---------------------------------------------------------------------------------------------

// Tolerances for the level set of a box. tools::meshToLevelSet stores at each voxel centre the
// exact distance to the nearest triangle (float), signed by an inside/outside flood fill. Near
// the middle of a face the exact SDF is affine (distance to a plane), and trilinear
// interpolation reproduces an affine function exactly, so the only error left is float32
// rounding (~1e-7 relative, i.e. ~1e-5 voxel here). We allow 0.01 voxel, far above rounding
// and far below the 0.5-voxel error a wrong neighbour or a shifted surface would give.
constexpr double FACE_TOLERANCE_VOXELS = 0.01;

TEST(MeshToSdf, ClosedObjBoxMatchesTheAnalyticDistance)
{
    const fs::path dir = freshDir("mesh_obj");
    // Faces half-way between voxel centres (0.25 / 0.02 = 12.5 voxels); centre on a voxel centre.
    const Vec3d lo(-0.25), hi(0.25);
    writeText(dir / "box.obj", boxObj(lo, hi));

    vdbio::MeshToSdfOptions options;
    options.voxelSize = 0.02;
    options.halfWidth = 16; // wider than the 12.5-voxel half edge: the band reaches the centre
    vdbio::MeshStats stats;
    const openvdb::FloatGrid::Ptr grid =
        vdbio::meshToLevelSet((dir / "box.obj").string(), options, &stats);

    EXPECT_EQ(stats.vertices, 8u); // 24 OBJ vertices (one normal per face) welded to 8
    EXPECT_EQ(stats.triangles, 12u);
    EXPECT_EQ(stats.boundaryEdges, 0u);
    EXPECT_EQ(stats.nonManifoldEdges, 0u);
    EXPECT_EQ(grid->getName(), "surface");
    EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_FLOAT_EQ(grid->background(), float(16 * 0.02));

    // The centre is a voxel centre, so its value is read, not interpolated: the exact -0.25 m
    // up to float rounding (same tolerance).
    const double centre = grid->tree().getValue(openvdb::Coord(0, 0, 0));
    const double faceError = maxFaceErrorVoxels(*grid, lo, hi);
    std::printf("[measured] OBJ box: phi(centre) = %.7f m (exact -0.25), max face error "
                "%.2e voxels, %llu active voxels\n",
                centre, faceError, static_cast<unsigned long long>(grid->activeVoxelCount()));
    EXPECT_NEAR(centre, -0.25, FACE_TOLERANCE_VOXELS * options.voxelSize);
    EXPECT_LT(faceError, FACE_TOLERANCE_VOXELS);
}

TEST(MeshToSdf, AsciiPlyWithScaleAndRoleIsWrittenToAVdb)
{
    const fs::path dir = freshDir("mesh_ply");
    // In mesh units; with scale 0.5 and voxel 0.01 m every face lies half-way between voxel
    // centres (e.g. x: 0.13 * 0.5 / 0.01 = 6.5 voxels).
    const Vec3d lo(0.13, -0.27, 0.05), hi(0.53, 0.33, 0.45);
    writeText(dir / "box.ply", boxPly(lo, hi));

    vdbio::MeshToSdfOptions options;
    options.voxelSize = 0.01;
    options.scale = 0.5;
    options.gridName = "tank";
    options.role = "liquid";
    vdbio::MeshStats stats;
    const std::string vdbPath = (dir / "tank.vdb").string();
    vdbio::convertMeshFile((dir / "box.ply").string(), vdbPath, options, &stats);
    EXPECT_EQ(stats.vertices, 8u);
    EXPECT_EQ(stats.triangles, 12u); // 6 quads triangulated
    EXPECT_EQ(stats.boundaryEdges, 0u);
    const Vec3d wlo = lo * 0.5, whi = hi * 0.5;
    // Bounds come from float vertices: float rounding only (~1e-7 relative).
    EXPECT_NEAR((stats.boundsMin - wlo).length(), 0.0, 1e-6);
    EXPECT_NEAR((stats.boundsMax - whi).length(), 0.0, 1e-6);

    // Read it back: the file must carry the name, class, role and the scaled geometry.
    openvdb::io::File file(vdbPath);
    file.open();
    const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("tank"));
    file.close();
    ASSERT_TRUE(grid);
    EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
    ASSERT_TRUE(grid->metaValue<std::string>("ghostfx_role") == "liquid");
    EXPECT_DOUBLE_EQ(grid->voxelSize()[0], 0.01);
    const double faceError = maxFaceErrorVoxels(*grid, wlo, whi);
    std::printf("[measured] PLY box (scale 0.5): max face error %.2e voxels, %llu active voxels\n",
                faceError, static_cast<unsigned long long>(grid->activeVoxelCount()));
    EXPECT_LT(faceError, FACE_TOLERANCE_VOXELS); // see FACE_TOLERANCE_VOXELS
    // Beyond the 3-voxel band the inside reads -background, the outside +background.
    const float background = grid->background();
    EXPECT_EQ(grid->tree().getValue(grid->transform().worldToIndexCellCentered(0.5 * (wlo + whi))),
              -background);
    EXPECT_EQ(grid->tree().getValue(grid->transform().worldToIndexCellCentered(whi + Vec3d(0.1))),
              background);
}

TEST(MeshToSdf, OpenMeshReportsItsBoundaryEdges)
{
    const fs::path dir = freshDir("mesh_open");
    writeText(dir / "open.obj", boxObj(Vec3d(-0.25), Vec3d(0.25), /*withTop=*/false));
    vdbio::MeshToSdfOptions options;
    options.voxelSize = 0.02;
    vdbio::MeshStats stats;
    vdbio::meshToLevelSet((dir / "open.obj").string(), options, &stats);
    // A box without its top: 10 triangles, and the 4 rim edges of the missing face are open.
    EXPECT_EQ(stats.triangles, 10u);
    EXPECT_EQ(stats.boundaryEdges, 4u);
    EXPECT_EQ(stats.nonManifoldEdges, 0u);
}

TEST(MeshToSdf, ErrorsNameTheFileAndTheValue)
{
    const fs::path dir = freshDir("mesh_errors");
    writeText(dir / "box.obj", boxObj(Vec3d(-0.25), Vec3d(0.25)));
    vdbio::MeshToSdfOptions options;
    options.voxelSize = 0.02;

    const std::string missing = (dir / "missing.obj").string();
    std::string e = errorOf<IoError>([&] { vdbio::meshToLevelSet(missing, options); });
    EXPECT_EQ(e, "mesh file '" + missing + "': no such file");

    const std::string junk = (dir / "junk.ply").string();
    writeText(junk, "this is not a mesh\n");
    e = errorOf<IoError>([&] { vdbio::meshToLevelSet(junk, options); });
    EXPECT_TRUE(contains(e, "mesh file '" + junk + "': cannot read it as a mesh (")) << e;

    // Points and lines only: readable, but nothing bounds a volume.
    const std::string lines = (dir / "lines.obj").string();
    writeText(lines, "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n");
    e = errorOf<GridError>([&] { vdbio::meshToLevelSet(lines, options); });
    EXPECT_EQ(e, "mesh file '" + lines + "' contains no triangles");

    vdbio::MeshToSdfOptions bad = options;
    bad.voxelSize = 0;
    e = errorOf<ValueError>([&] { vdbio::meshToLevelSet((dir / "box.obj").string(), bad); });
    EXPECT_EQ(e, "voxelSize = 0: expected a voxel size > 0 (m)");

    bad = options;
    bad.halfWidth = 0.5;
    e = errorOf<ValueError>([&] { bad.validate(); });
    EXPECT_EQ(e, "halfWidth = 0.5: expected >= 1 (voxels)");

    bad = options;
    bad.role = "water";
    e = errorOf<ValueError>([&] { bad.validate(); });
    EXPECT_EQ(e, "role = 'water': expected one of solid, liquid, emitter, source (or none)");

    // A failed conversion leaves no output file behind.
    const std::string out = (dir / "out.vdb").string();
    errorOf<IoError>([&] { vdbio::convertMeshFile(junk, out, options); });
    EXPECT_FALSE(fs::exists(out));
}

// ---------------------------------------------------------------------------------------------
// preview
// ---------------------------------------------------------------------------------------------

namespace {

/// Alpha-weighted centroid of an image (pixels, origin at the top-left corner).
Vec3d alphaCentroid(const vdbio::RgbaImage& image)
{
    double sum = 0, sx = 0, sy = 0;
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
            const double a = image.pixel(x, y)[3];
            sum += a;
            sx += a * (x + 0.5);
            sy += a * (y + 0.5);
        }
    }
    return Vec3d(sx / sum, sy / sum, sum);
}

void expectTransparentCorners(const vdbio::RgbaImage& image)
{
    for (int y : {0, image.height - 1}) {
        for (int x : {0, image.width - 1}) {
            const float* p = image.pixel(x, y);
            // Rays through the corners miss the grid's bounding box: nothing is added, so the
            // background is exactly transparent black.
            EXPECT_EQ(p[0], 0.0f) << "corner " << x << "," << y;
            EXPECT_EQ(p[3], 0.0f) << "corner " << x << "," << y;
        }
    }
}

// A sphere of radius 0.1 m: a 0.2 m thick body, as in the preview's design note.
constexpr double SPHERE_RADIUS = 0.1;
constexpr double SPHERE_VOXEL = 0.005;
constexpr int IMAGE_W = 160, IMAGE_H = 90;

openvdb::FloatGrid::Ptr sphereLevelSet()
{
    auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(SPHERE_RADIUS), openvdb::Vec3f(0.0f), float(SPHERE_VOXEL));
    grid->setName("surface");
    return grid;
}

struct Rendered
{
    vdbio::PreviewSummary summary;
    vdbio::RgbaImage image;
    const float* centre = nullptr; ///< the centre pixel's rgba
    Vec3d centroid;                ///< alphaCentroid(image)
};

/// Render `grid` at IMAGE_W x IMAGE_H to the EXR `file`, read the image back and print its
/// centre pixel and alpha centroid as "[measured] <label>: ...".
Rendered renderAndRead(const openvdb::FloatGrid& grid, const fs::path& file, const char* label)
{
    vdbio::PreviewOptions options;
    options.width = IMAGE_W;
    options.height = IMAGE_H;
    Rendered r{vdbio::renderPreview(grid, options, file.string()), {}, nullptr, Vec3d(0)};
    r.image = vdbio::readExrImage(file.string());
    EXPECT_EQ(r.image.width, IMAGE_W);
    EXPECT_EQ(r.image.height, IMAGE_H);
    r.centre = r.image.pixel(IMAGE_W / 2, IMAGE_H / 2);
    r.centroid = alphaCentroid(r.image);
    const float* c = r.centre;
    std::printf("[measured] %s: centre pixel rgba = (%.3f, %.3f, %.3f, %.3f), alpha centroid "
                "(%.2f, %.2f) px, %.2f s\n",
                label, c[0], c[1], c[2], c[3], r.centroid.x(), r.centroid.y(), r.summary.seconds);
    return r;
}

} // namespace

TEST(Preview, FogSphereIsVisibleButNotBlackOnATransparentBackground)
{
    const fs::path dir = freshDir("preview_fog");
    openvdb::FloatGrid::Ptr fog = sphereLevelSet();
    openvdb::tools::sdfToFogVolume(*fog); // density 1 inside, 0 outside, ramp across the band
    fog->setName("density");

    const Rendered r = renderAndRead(*fog, dir / "fog.exr", "fog sphere");
    EXPECT_EQ(r.summary.gridClass, "fog volume");
    const float* c = r.centre;
    // Through the middle the optical depth is 10 /m * 0.2 m = 2 (PreviewOptions::extinction),
    // so alpha = 1 - e^-2 = 0.86, a little less for the ramp in the band: require 0.7 .. 0.9.
    EXPECT_GT(c[3], 0.7f);
    EXPECT_LT(c[3], 0.9f);
    // Lit from the camera side with albedo 0.9, a front-lit half-space reflects about half the
    // light (single scattering, in and out through the same depth): require "clearly not black"
    // (> 0.15) and not saturated (< 0.9) on every channel.
    for (int k = 0; k < 3; ++k) {
        EXPECT_GT(c[k], 0.15f);
        EXPECT_LT(c[k], 0.9f);
    }
    expectTransparentCorners(r.image);
    // Auto-framing centres the sphere; its voxelised band is symmetric to one voxel, which
    // projects to less than a pixel here: allow 1 pixel.
    EXPECT_NEAR(r.centroid.x(), IMAGE_W / 2.0, 1.0);
    EXPECT_NEAR(r.centroid.y(), IMAGE_H / 2.0, 1.0);
}

TEST(Preview, PngMatchesTheExrThroughTheSrgbCurve)
{
    const fs::path dir = freshDir("preview_png");
    openvdb::FloatGrid::Ptr fog = sphereLevelSet();
    openvdb::tools::sdfToFogVolume(*fog);
    fog->setName("density");
    vdbio::PreviewOptions options;
    options.width = IMAGE_W;
    options.height = IMAGE_H;
    vdbio::renderPreview(*fog, options, (dir / "fog.exr").string());
    vdbio::renderPreview(*fog, options, (dir / "fog.png").string());
    const vdbio::RgbaImage exr = vdbio::readExrImage((dir / "fog.exr").string());
    const vdbio::RgbaImage png = vdbio::readExrImage((dir / "fog.png").string());
    ASSERT_EQ(png.width, IMAGE_W);
    ASSERT_EQ(png.height, IMAGE_H);
    // Every PNG value is the sRGB encoding of the EXR's (half-float) value, to half an 8-bit step
    // plus the half-float rounding of the EXR (about 1e-3 relative, so 1 step at most).
    float worst = 0;
    for (std::size_t i = 0; i < exr.rgba.size(); ++i) {
        const float linear = std::clamp(exr.rgba[i], 0.0f, 1.0f);
        const float expected = (i % 4 == 3) ? linear
                               : linear <= 0.0031308f
                                   ? 12.92f * linear
                                   : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
        worst = std::max(worst, std::abs(png.rgba[i] - expected));
    }
    std::printf("[measured] PNG vs sRGB(EXR): worst difference %.4f (8-bit step %.4f)\n", worst,
                1 / 255.0);
    EXPECT_LE(worst, 1.5f / 255.0f);
}

TEST(Preview, LevelSetSphereIsOpaqueAndShaded)
{
    const fs::path dir = freshDir("preview_surface");
    const openvdb::FloatGrid::Ptr surface = sphereLevelSet();
    const Rendered r = renderAndRead(*surface, dir / "surface.exr", "level-set sphere");
    EXPECT_EQ(r.summary.gridClass, "level set");
    const float* c = r.centre;
    EXPECT_EQ(c[3], 1.0f); // a surface hit is opaque
    // The centre of the sphere faces the camera; the key light is 33 degrees off the view
    // direction (Preview.cc: toCamera + 0.5 up - 0.4 right), so Lambert gives cos = 0.84 and,
    // with ambient 0.2, a shade of 0.2 + 0.8 * 0.84 = 0.87 of the albedo (0.75, 0.8, 0.88).
    // Require clearly lit (> 0.5) and not above the albedo (<= 0.9).
    for (int k = 0; k < 3; ++k) {
        EXPECT_GT(c[k], 0.5f);
        EXPECT_LE(c[k], 0.9f);
    }
    expectTransparentCorners(r.image);
    EXPECT_NEAR(r.centroid.x(), IMAGE_W / 2.0, 1.0); // as for the fog sphere
    EXPECT_NEAR(r.centroid.y(), IMAGE_H / 2.0, 1.0);
}

TEST(Preview, FromFilePicksAGridAndErrorsNameFileAndGrid)
{
    const fs::path dir = freshDir("preview_errors");
    const openvdb::FloatGrid::Ptr surface = sphereLevelSet();
    const openvdb::Vec3SGrid::Ptr velocity = openvdb::Vec3SGrid::create();
    velocity->setName("vel");
    velocity->tree().setValue(openvdb::Coord(0), openvdb::Vec3s(1.0f));
    const std::string vdb = (dir / "frame.vdb").string();
    openvdb::io::File(vdb).write({velocity, surface});

    vdbio::PreviewOptions options;
    options.width = 32;
    options.height = 18;
    // No "density": the default is "surface".
    const std::string exr = (dir / "frame.exr").string();
    EXPECT_EQ(vdbio::renderPreviewFromFile(vdb, options, exr).gridName, "surface");
    EXPECT_TRUE(fs::exists(exr));

    options.grid = "density";
    std::string e = errorOf<GridError>([&] { vdbio::renderPreviewFromFile(vdb, options, exr); });
    // (io::File stores the grids in its own order.)
    EXPECT_TRUE(contains(e, "grid 'density' not found in '" + vdb + "' (grids: ")) << e;
    EXPECT_TRUE(contains(e, "'vel'") && contains(e, "'surface'")) << e;

    options.grid = "vel";
    e = errorOf<GridError>([&] { vdbio::renderPreviewFromFile(vdb, options, exr); });
    EXPECT_EQ(e, "grid 'vel' in '" + vdb
                     + "' has value type vec3s: preview renders float "
                       "grids (fog volumes or level sets)");

    options.grid = "";
    const std::string missing = (dir / "missing.vdb").string();
    e = errorOf<IoError>([&] { vdbio::renderPreviewFromFile(missing, options, exr); });
    EXPECT_EQ(e, "'" + missing + "': no such file");

    const std::string noFolder = (dir / "no" / "such" / "folder.exr").string();
    e = errorOf<IoError>([&] { vdbio::renderPreviewFromFile(vdb, options, noFolder); });
    EXPECT_EQ(e, "preview image '" + noFolder + "': folder '" + (dir / "no" / "such").string()
                     + "' does not exist");

    options.width = 0;
    e = errorOf<ValueError>([&] { vdbio::renderPreviewFromFile(vdb, options, exr); });
    EXPECT_EQ(e, "preview width = 0: expected 1 to 16384 pixels");
}

// ---------------------------------------------------------------------------------------------
// info
// ---------------------------------------------------------------------------------------------

TEST(Info, DescribesTheGridsAndPointsOfAVdbFile)
{
    const fs::path dir = freshDir("info_vdb");
    const openvdb::FloatGrid::Ptr surface = sphereLevelSet();
    surface->insertMeta("ghostfx_role", openvdb::StringMetadata("liquid"));
    const openvdb::FloatGrid::Ptr density = surface->deepCopy();
    openvdb::tools::sdfToFogVolume(*density);
    density->setName("density");

    const std::string vdb = (dir / "frame.vdb").string();
    openvdb::io::File(vdb).write({surface, density});

    // 100 particles on a line, 1 cm apart, written as ghostfx writes its particle files
    // (vdbio::writePointsFile: P, v, id, density, pressure).
    std::vector<sph::Vec3> positions;
    for (int i = 0; i < 100; ++i) positions.emplace_back(sph::Real(0.01 * i), 0, 0);
    sph::ParticleSet particles;
    particles.addBatch(positions, sph::Real(1e-3), sph::ParticleKind::Liquid);
    const std::string pointsVdb = (dir / "particles.vdb").string();
    vdbio::writePointsFile(pointsVdb, particles, vdbio::PointsOptions());

    const std::string text = vdbio::describeFile(vdb);
    std::printf("[measured] ghostfx info on a .vdb:\n%s", text.c_str());
    for (const std::string& part :
         {std::string("grid 'surface'"), std::string("class:           Level Set"),
          "active voxels:   " + std::to_string(surface->activeVoxelCount()),
          std::string("voxel size:      0.005 m"), std::string("ghostfx_role (string): liquid"),
          std::string("grid 'density'"), std::string("class:           Fog Volume"),
          "active voxels:   " + std::to_string(density->activeVoxelCount())}) {
        EXPECT_TRUE(contains(text, part)) << "missing: " << part;
    }

    const std::string pointsText = vdbio::describeFile(pointsVdb);
    std::printf("[measured] ghostfx info on a particles .vdb:\n%s", pointsText.c_str());
    // P is 12 bytes (vec3s), v 12 (vec3s), id 8 (int64), density and pressure 4 each (float).
    for (const char* part :
         {"grid 'particles'", "points:          100", "P              vec3s (codec null, 12 bytes)",
          "id ", "bytes per point: 40 in attributes"}) {
        EXPECT_TRUE(contains(pointsText, part)) << "missing: " << part;
    }
    // Ranges from vdbio::readPointsGrid, as Python's read_points returns the columns: x runs
    // over 0 .. 0.99 m (float 0.99 prints as 0.99 at 6 digits), the mean of 0.01 i over
    // i < 100 is 0.495 m; ids are 0 .. 99; the particles are at rest.
    for (const char* part :
         {"attribute ranges (min .. max, mean; P in world space, m):\n",
          "    P              [0, 0, 0] .. [0.99, 0, 0], mean [0.495, 0, 0]\n",
          "    v              [0, 0, 0] .. [0, 0, 0], mean [0, 0, 0]\n",
          "    id             0 .. 99, mean 49.5\n"}) {
        EXPECT_TRUE(contains(pointsText, part)) << "missing: " << part;
    }

    // Points and volumes in one file: the points' lines must not change how the next grid's
    // numbers are printed (a regression: the level set's background read "0.01").
    openvdb::io::File pointsFile(pointsVdb);
    pointsFile.open();
    const std::string mixedVdb = (dir / "mixed.vdb").string();
    openvdb::io::File(mixedVdb).write({pointsFile.readGrid("particles"), surface});
    pointsFile.close();
    const std::string mixedText = vdbio::describeFile(mixedVdb);
    EXPECT_TRUE(contains(mixedText, "background:      0.015\n")) << mixedText;
    EXPECT_TRUE(contains(mixedText, "voxel size:      0.005 m")) << mixedText;

    const std::string missing = (dir / "missing.vdb").string();
    EXPECT_EQ(errorOf<IoError>([&] { vdbio::describeFile(missing); }),
              "'" + missing + "': no such file");
    const std::string text2 = (dir / "notes.txt").string();
    writeText(text2, "hello\n");
    EXPECT_EQ(errorOf<IoError>([&] { vdbio::describeFile(text2); }),
              "'" + text2 + "': unknown kind of file '.txt': expected .vdb, .h5 or .hdf5");
    const std::string fake = (dir / "fake.vdb").string();
    writeText(fake, "hello\n");
    EXPECT_TRUE(contains(errorOf<IoError>([&] { vdbio::describeFile(fake); }),
                         "'" + fake + "': cannot read as a .vdb file ("));
}

TEST(Info, DescribesGroupsDatasetsAndAttributesOfAnHdf5File)
{
#if GHOSTFX_TEST_HDF5
    const fs::path dir = freshDir("info_h5");
    const std::string h5 = (dir / "stats.h5").string();
    {
        H5::H5File file(h5, H5F_ACC_TRUNC);
        const H5::DataSpace scalar(H5S_SCALAR);
        const int schemaVersion = 1;
        file.createAttribute("schema_version", H5::PredType::NATIVE_INT, scalar)
            .write(H5::PredType::NATIVE_INT, &schemaVersion);
        const double time = 0.25;
        file.createAttribute("time", H5::PredType::NATIVE_DOUBLE, scalar)
            .write(H5::PredType::NATIVE_DOUBLE, &time);
        const H5::StrType text(H5::PredType::C_S1, H5T_VARIABLE);
        file.createAttribute("format", text, scalar).write(text, std::string("ghostfx test"));
        const char* columns[3] = {"frame", "time", "dt"};
        const hsize_t three = 3;
        file.createAttribute("columns", text, H5::DataSpace(1, &three)).write(text, columns);
        H5::Group group = file.createGroup("/particles");
        const long long count = 10;
        group.createAttribute("count_liquid", H5::PredType::NATIVE_LLONG, scalar)
            .write(H5::PredType::NATIVE_LLONG, &count);
        const hsize_t dims[2] = {10, 3};
        std::vector<float> values(30, 1.0f);
        group.createDataSet("position", H5::PredType::NATIVE_FLOAT, H5::DataSpace(2, dims))
            .write(values.data(), H5::PredType::NATIVE_FLOAT);
    }
    const std::string text = vdbio::describeFile(h5);
    std::printf("[measured] ghostfx info on an .h5:\n%s", text.c_str());
    for (const char* part :
         {"@schema_version = 1 (int32)", "@time = 0.25 (float64)", "@format = \"ghostfx test\"",
          "@columns = [\"frame\", \"time\", \"dt\"]", "/particles/  (group)",
          "@count_liquid = 10 (int64)", "/particles/position  (dataset float32 [10 x 3]"}) {
        EXPECT_TRUE(contains(text, part)) << "missing: " << part;
    }
    const std::string fake = (dir / "fake.h5").string();
    writeText(fake, "hello\n");
    EXPECT_EQ(errorOf<IoError>([&] { vdbio::describeFile(fake); }),
              "'" + fake + "': not an HDF5 file");
#else
    GTEST_SKIP() << "ghostfx_vdbio_tests does not link HDF5 (add HDF5::HDF5 to its LIBS in "
                    "tests/CMakeLists.txt to run this test)";
#endif
}
