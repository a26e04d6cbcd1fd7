/// @file   test_scene_preview.cc
/// @brief  The scene preview (ScenePreview.h): solids and liquid drawn where the scene puts
///         them in their own colours, containers cut away so their contents show, fog in front.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/ScenePreview.h>

#include "common/Expect.h"

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <cmath>

using namespace ghostfx;
using vdbio::PreviewLayer;

namespace {

constexpr int W = 160, H = 90;

PreviewLayer surface(const std::string& name, openvdb::FloatGrid::Ptr grid,
                     const std::array<float, 3>& albedo)
{
    PreviewLayer l;
    l.name = name;
    l.grid = grid;
    l.albedo = albedo;
    return l;
}

vdbio::PreviewOptions frontView()
{
    vdbio::PreviewOptions o;
    o.width = W;
    o.height = H;
    o.azimuth = 0; // camera on +z, looking towards -z: x to the right, y up
    o.elevation = 0;
    return o;
}

/// Mean colour over the image's pixels of columns [x0, x1) that are covered (alpha > 0.5).
std::array<float, 3> meanColour(const vdbio::RgbaImage& image, int x0, int x1)
{
    std::array<float, 3> sum{0, 0, 0};
    int n = 0;
    for (int y = 0; y < image.height; ++y) {
        for (int x = x0; x < x1; ++x) {
            const float* p = image.pixel(x, y);
            if (p[3] <= 0.5f) continue;
            for (int c = 0; c < 3; ++c) sum[c] += p[c];
            ++n;
        }
    }
    for (float& c : sum) c /= float(std::max(n, 1));
    return sum;
}

/// A closed box container: walls `wall` (m) thick around the inside [-a, a]^3.
openvdb::FloatGrid::Ptr closedTank(double a, double wall, float voxel)
{
    const openvdb::Vec3d outerLo(-a - wall), outerHi(a + wall), innerLo(-a), innerHi(a);
    auto sdf = [&](const openvdb::Vec3d& x) {
        return std::max(sph::boxSignedDistance(x, outerLo, outerHi),
                        -sph::boxSignedDistance(x, innerLo, innerHi));
    };
    return sph::levelSetFromSdf(sdf, sph::Aabb{sph::Vec3(outerLo), sph::Vec3(outerHi)}, voxel);
}

} // namespace

TEST(ScenePreview, SolidAndLiquidAppearWhereTheSceneHasThemInTheirColours)
{
    const auto dir = ghostfx::testing::freshDir("scene_preview");
    // A grey block on the left (x < 0), a blue drop on the right (x > 0), seen from the front.
    const std::vector<PreviewLayer> layers = {
        surface("block",
                sph::makeBoxLevelSet(sph::Vec3(-0.3f, -0.1f, -0.1f), sph::Vec3(-0.1f, 0.1f, 0.1f),
                                     0.01f),
                vdbio::SOLID_ALBEDO),
        surface("drop", sph::makeSphereLevelSet(sph::Vec3(0.2f, 0.0f, 0.0f), 0.1f, 0.01f),
                vdbio::LIQUID_ALBEDO)};
    const std::string png = (dir / "scene.png").string();
    const vdbio::ScenePreviewSummary s =
        vdbio::renderScenePreview(layers, frontView(), openvdb::BBoxd(), png);
    std::printf("[measured] block %zu px, drop %zu px, %.3f s\n", s.pixels[0], s.pixels[1],
                s.seconds);
    // At about 1 cm per pixel (the camera frames the pair's bounding sphere, r = 0.33 m, in 90
    // rows) the 20 cm block covers about 400 pixels and the 10 cm drop about 310.
    EXPECT_GT(s.pixels[0], 300u);
    EXPECT_GT(s.pixels[1], 200u);
    const vdbio::RgbaImage image = vdbio::readExrImage(png);
    ASSERT_EQ(image.width, W);
    const std::array<float, 3> left = meanColour(image, 0, W / 2),
                               right = meanColour(image, W / 2, W);
    // The solid's albedo is warm grey (r > b), the liquid's blue (b > 2 r): the halves show them.
    EXPECT_GT(left[0], left[2]) << "left half: the grey block";
    EXPECT_GT(right[2], 2 * right[0]) << "right half: the blue drop";
    // Nothing is drawn in the image's top-left corner (the background stays transparent).
    EXPECT_EQ(image.pixel(0, 0)[3], 0.0f);

    // An opaque background shows there instead, and the drop still covers its own pixels.
    vdbio::PreviewOptions dark = frontView();
    dark.background = {0.16f, 0.17f, 0.19f, 1.0f};
    const std::string exr = (dir / "dark.exr").string();
    vdbio::renderScenePreview(layers, dark, openvdb::BBoxd(), exr);
    const vdbio::RgbaImage onDark = vdbio::readExrImage(exr);
    const float* corner = onDark.pixel(0, 0);
    EXPECT_NEAR(corner[0], 0.16f, 1e-3f); // half floats: 3 significant digits
    EXPECT_NEAR(corner[2], 0.19f, 1e-3f);
    EXPECT_EQ(corner[3], 1.0f);
    // The drop's centre, 0.2 m right of the frame's centre at about 1 cm per pixel.
    const float* drop = onDark.pixel(W / 2 + 20, H / 2);
    EXPECT_GT(drop[2], 2 * drop[0]) << "the drop is still blue over the background";
    EXPECT_GT(drop[2], 0.3f);
    dark.background[0] = 2.0f;
    EXPECT_THROW(vdbio::renderScenePreview(layers, dark, openvdb::BBoxd(), exr), ValueError);
}

TEST(ScenePreview, AContainerIsCutAwaySoItsContentsShow)
{
    const auto dir = ghostfx::testing::freshDir("scene_preview_cut");
    PreviewLayer tank = surface("tank", closedTank(0.2, 0.03, 0.01f), vdbio::SOLID_ALBEDO);
    const PreviewLayer drop =
        surface("drop", sph::makeSphereLevelSet(sph::Vec3(0.0f, -0.1f, 0.0f), 0.08f, 0.01f),
                vdbio::LIQUID_ALBEDO);
    vdbio::PreviewOptions view = frontView();
    view.elevation = 25;
    const std::string closed = (dir / "closed.exr").string(), cut = (dir / "cut.exr").string();
    const auto hidden = vdbio::renderScenePreview({tank, drop}, view, openvdb::BBoxd(), closed);
    tank.cutaway = true;
    const auto shown = vdbio::renderScenePreview({tank, drop}, view, openvdb::BBoxd(), cut);
    std::printf("[measured] closed tank: drop %zu px; cut away: drop %zu px, tank %zu px\n",
                hidden.pixels[1], shown.pixels[1], shown.pixels[0]);
    EXPECT_EQ(hidden.pixels[1], 0u) << "a closed tank hides the drop";
    // The drop's silhouette (radius 8 cm at about 0.9 cm per pixel) covers about 250 pixels.
    EXPECT_GT(shown.pixels[1], 150u);
    EXPECT_GT(shown.pixels[0], 1000u) << "the far walls and the floor are still drawn";
}

TEST(ScenePreview, FogLiesInFrontOfTheSurfaceBehindIt)
{
    const auto dir = ghostfx::testing::freshDir("scene_preview_fog");
    openvdb::FloatGrid::Ptr fog =
        sph::makeSphereLevelSet(sph::Vec3(0.0f, 0.0f, 0.1f), 0.08f, 0.01f);
    openvdb::tools::sdfToFogVolume(*fog);
    PreviewLayer gas = surface("gas", fog, vdbio::GAS_ALBEDO);
    gas.kind = PreviewLayer::Kind::Fog;
    const PreviewLayer wall = surface(
        "wall",
        sph::makeBoxLevelSet(sph::Vec3(-0.3f, -0.3f, -0.1f), sph::Vec3(0.3f, 0.3f, -0.05f), 0.01f),
        vdbio::SOLID_ALBEDO);
    const std::string exr = (dir / "fog.exr").string();
    const auto s = vdbio::renderScenePreview({wall, gas}, frontView(), openvdb::BBoxd(), exr);
    const vdbio::RgbaImage image = vdbio::readExrImage(exr);
    // At the centre the ray crosses 0.16 m of gas (optical depth 1.6 at extinction 10 /m, so
    // 80 % of the wall's light is held back) before the wall: whiter than the bare wall at the
    // edge of the frame, where no gas is.
    const float* centre = image.pixel(W / 2, H / 2);
    const float* edge = image.pixel(W / 2 + 20, H / 2); // 0.2 m right of the gas: bare wall
    std::printf(
        "[measured] fog over wall: centre rgb (%.3f %.3f %.3f), bare wall (%.3f %.3f %.3f)\n",
        centre[0], centre[1], centre[2], edge[0], edge[1], edge[2]);
    EXPECT_GT(s.pixels[1], 100u); // the 8 cm gas ball, where it is more than 5 % opaque
    EXPECT_EQ(centre[3], 1.0f);
    EXPECT_GT(centre[2] - centre[0], -0.01f); // the gas is neutral white, not the wall's warm grey
    EXPECT_GT(edge[0] - edge[2], 0.02f);      // the bare wall is warm grey
    // Bad input is refused before anything is written.
    EXPECT_THROW(
        vdbio::renderScenePreview({}, frontView(), openvdb::BBoxd(), (dir / "none.exr").string()),
        ValueError);
}

TEST(ScenePreview, FixedSolidHitsAreKeptBetweenFramesAndChangeNothing)
{
    // A cut-away tank (fixed) around a drop that moves between "frames", in a fixed frame box:
    // the tank's hits are computed once and reused while the camera and the tank stay; the
    // images are identical, pixel for pixel, to ones drawn without the cache.
    const auto dir = ghostfx::testing::freshDir("scene_preview_cache");
    PreviewLayer tank = surface("tank", closedTank(0.2, 0.03, 0.01f), vdbio::SOLID_ALBEDO);
    tank.cutaway = true;
    tank.fixed = true;
    vdbio::PreviewOptions view = frontView();
    view.elevation = 25;
    const openvdb::BBoxd box(openvdb::Vec3d(-0.25), openvdb::Vec3d(0.25));
    vdbio::PreviewCache cache;
    auto draw = [&](float dropY, const PreviewLayer& solid, vdbio::PreviewCache* c,
                    const std::string& name) {
        const PreviewLayer drop =
            surface("drop", sph::makeSphereLevelSet(sph::Vec3(0.0f, dropY, 0.0f), 0.06f, 0.01f),
                    vdbio::LIQUID_ALBEDO);
        const std::string path = (dir / name).string();
        const auto s = vdbio::renderScenePreview({solid, drop}, view, box, path, c);
        return std::make_pair(s.pixels, vdbio::readExrImage(path));
    };
    auto same = [](const vdbio::RgbaImage& a, const vdbio::RgbaImage& b) {
        for (int y = 0; y < a.height; ++y) {
            for (int x = 0; x < a.width; ++x) {
                for (int c = 0; c < 4; ++c) {
                    if (a.pixel(x, y)[c] != b.pixel(x, y)[c]) return false;
                }
            }
        }
        return true;
    };
    for (int frame = 0; frame < 3; ++frame) {
        const float y = -0.1f + 0.05f * float(frame);
        const auto cached = draw(y, tank, &cache, "cached.exr");
        const auto plain = draw(y, tank, nullptr, "plain.exr");
        EXPECT_EQ(cached.first, plain.first) << "frame " << frame;
        EXPECT_TRUE(same(cached.second, plain.second)) << "frame " << frame;
        EXPECT_GT(plain.first[1], 50u) << "the drop shows through the cut-away tank";
    }
    EXPECT_EQ(cache.computed, 1u);
    EXPECT_EQ(cache.reused, 2u);
    // Moving the tank (or the camera) recomputes its hits.
    tank.translation = openvdb::Vec3d(0.02, 0, 0);
    const auto moved = draw(0.0f, tank, &cache, "moved.exr");
    const auto movedPlain = draw(0.0f, tank, nullptr, "moved_plain.exr");
    EXPECT_TRUE(same(moved.second, movedPlain.second));
    EXPECT_EQ(cache.computed, 2u);
}
