/// @file   test_plot.cc
/// @brief  Error-versus-cost plots: the Pareto front, the PNG read back pixel by pixel, and the
///         errors a bad plot gives before anything is written.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/Plot.h>

// Private to vdbio, included only to read the image back.
#include "../../vdbio/src/PngFile.h"

#include "common/Expect.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace ghostfx;
using vdbio::PlotPoint;
using vdbio::PlotSpec;

namespace {

using ghostfx::testing::freshDir;

std::size_t fileCount(const fs::path& dir)
{
    return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

using ghostfx::testing::slurp;

using ghostfx::testing::contains;
using ghostfx::testing::errorOf;

/// A PNG read back as 8-bit RGBA.
struct Image
{
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;

    explicit Image(const std::string& path) { rgba = vdbio::readPngRgba8(path, width, height); }
    std::array<int, 3> rgb(int x, int y) const
    {
        const std::uint8_t* p = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
        return {p[0], p[1], p[2]};
    }
    /// Darkest channel value in the 3x3 pixels around (x, y).
    int darkestAround(int x, int y) const
    {
        int darkest = 255;
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                const auto c = rgb(x + dx, y + dy);
                darkest = std::min({darkest, c[0], c[1], c[2]});
            }
        }
        return darkest;
    }
};

std::array<int, 3> asInts(const std::array<std::uint8_t, 3>& c) { return {c[0], c[1], c[2]}; }

/// Two series, well apart on a log-log plot: a three-point front (series "fast") and two
/// dominated points (series "slow").
PlotSpec twoSeries()
{
    PlotSpec spec;
    spec.title = "Dam break";
    spec.xLabel = "cost (s)";
    spec.yLabel = "density error";
    spec.width = 640;
    spec.height = 420;
    spec.points = {{1.0, 1.0, "fast", "h=0.04"},
                   {10.0, 0.1, "fast", "h=0.02"},
                   {100.0, 0.01, "fast", "h=0.01"},
                   {30.0, 3.0, "slow", "a"},
                   {1000.0, 0.5, "slow", "b"}};
    return spec;
}

} // namespace

TEST(PlotParetoFront, HandMadeSetGivesExactlyTheUnbeatenPointsSortedByX)
{
    const std::vector<PlotPoint> points = {{1.0, 10.0, "", "a"},  // front
                                           {2.0, 5.0, "", "b"},   // front
                                           {3.0, 6.0, "", "c"},   // beaten by b in x and y
                                           {2.0, 7.0, "", "d"},   // same x as b, larger y
                                           {4.0, 1.0, "", "e"},   // front
                                           {5.0, 1.0, "", "f"},   // same y as e, larger x
                                           {0.5, 20.0, "", "g"}}; // front: cheapest
    EXPECT_EQ(vdbio::paretoFront(points), (std::vector<std::size_t>{6, 0, 1, 4}));
}

TEST(PlotParetoFront, TiesSinglePointAndNonFiniteValues)
{
    // Identical points beat neither each other: both on the front, or both off it.
    EXPECT_EQ(vdbio::paretoFront({{1, 1, "", ""}, {2, 0.5, "", ""}, {1, 1, "", ""}}),
              (std::vector<std::size_t>{0, 2, 1}));
    EXPECT_EQ(vdbio::paretoFront({{2, 2, "", ""}, {1, 1, "", ""}, {2, 2, "", ""}}),
              (std::vector<std::size_t>{1}));
    EXPECT_EQ(vdbio::paretoFront({{3, 4, "", ""}}), (std::vector<std::size_t>{0}));
    EXPECT_TRUE(vdbio::paretoFront({}).empty());
    // A NaN point is never on the front and beats nothing.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(vdbio::paretoFront({{nan, 0.1, "", ""}, {2, 2, "", ""}}),
              (std::vector<std::size_t>{1}));
}

TEST(Plot, WritesAPngOfTheRequestedSize)
{
    const fs::path dir = freshDir("plot_size");
    const std::string path = (dir / "study.png").string();
    PlotSpec spec = twoSeries();
    spec.width = 517;
    spec.height = 333;
    vdbio::writePlotPng(path, spec);
    const Image image(path);
    EXPECT_EQ(image.width, 517);
    EXPECT_EQ(image.height, 333);
    EXPECT_EQ(image.rgba.size(), std::size_t(517) * 333 * 4);
    // Opaque white background in the top-left corner (inside the outer margin).
    EXPECT_EQ(image.rgb(1, 1), (std::array<int, 3>{255, 255, 255}));
    EXPECT_EQ(image.rgba[3], 255);
    EXPECT_EQ(fileCount(dir), 1u) << "a temporary file was left behind";
}

TEST(Plot, EachPointIsDrawnInItsSeriesColourWhereTheAxesMapIt)
{
    const fs::path dir = freshDir("plot_pixels");
    const std::string path = (dir / "study.png").string();
    const PlotSpec spec = twoSeries();
    vdbio::writePlotPng(path, spec);
    const Image image(path);

    // Series are numbered in order of first appearance: "fast" 0, "slow" 1. Marker centres
    // are fully covered, and the 8-bit sRGB palette survives the linear-float round trip
    // exactly, so the match is exact.
    for (const PlotPoint& p : spec.points) {
        const auto at = vdbio::plotPixelOf(spec, p.x, p.y);
        ASSERT_GE(at[0], 0);
        ASSERT_LT(at[0], image.width);
        ASSERT_GE(at[1], 0);
        ASSERT_LT(at[1], image.height);
        const std::size_t series = p.series == "fast" ? 0 : 1;
        EXPECT_EQ(image.rgb(at[0], at[1]), asInts(vdbio::plotSeriesColour(series)))
            << "point " << p.label << " at pixel (" << at[0] << ", " << at[1] << ")";
    }
    EXPECT_NE(vdbio::plotSeriesColour(0), vdbio::plotSeriesColour(1));

    // Log axes: the three front points are a decade apart in both x and y, so their pixels are
    // equally spaced (to the 1-pixel rounding of each), x growing right and y growing up.
    const auto a = vdbio::plotPixelOf(spec, 1.0, 1.0), b = vdbio::plotPixelOf(spec, 10.0, 0.1),
               c = vdbio::plotPixelOf(spec, 100.0, 0.01);
    EXPECT_GT(b[0], a[0]);
    EXPECT_GT(b[1], a[1]);
    EXPECT_NEAR(c[0] - b[0], b[0] - a[0], 1);
    EXPECT_NEAR(c[1] - b[1], b[1] - a[1], 1);

    // The front is a dark line: halfway between two front points (no marker there) there is a
    // dark pixel; without markPareto the same place is background or grid (>= 200).
    const int midX = (a[0] + b[0]) / 2, midY = (a[1] + b[1]) / 2;
    EXPECT_LT(image.darkestAround(midX, midY), 100);
    PlotSpec plain = spec;
    plain.markPareto = false;
    vdbio::writePlotPng(path, plain);
    EXPECT_GE(Image(path).darkestAround(midX, midY), 200);
}

TEST(Plot, NonPositiveValueOnALogAxisNamesThePointAndWritesNothing)
{
    const fs::path dir = freshDir("plot_errors");
    const std::string path = (dir / "study.png").string();

    PlotSpec spec = twoSeries();
    spec.points.push_back({5.0, 0.0, "fast", "h=0.005"});
    std::string text = errorOf<ValueError>([&] { vdbio::writePlotPng(path, spec); });
    EXPECT_TRUE(contains(text, "'h=0.005'")) << text;
    EXPECT_TRUE(contains(text, "y = 0")) << text;
    EXPECT_TRUE(contains(text, "log y axis")) << text;
    EXPECT_TRUE(contains(text, path)) << text;

    spec.points.back() = {-2.0, 0.3, "slow", "cfl=0.4"};
    text = errorOf<ValueError>([&] { vdbio::writePlotPng(path, spec); });
    EXPECT_TRUE(contains(text, "'cfl=0.4'")) << text;
    EXPECT_TRUE(contains(text, "x = -2")) << text;
    EXPECT_EQ(fileCount(dir), 0u) << "something was written for a failed plot";

    // The same values are fine on linear axes.
    spec.logX = spec.logY = false;
    spec.points.back() = {-2.0, 0.0, "slow", "cfl=0.4"};
    vdbio::writePlotPng(path, spec);
    EXPECT_TRUE(fs::exists(path));
}

TEST(Plot, BadSpecsAreRejectedAndLeaveTheExistingFileIntact)
{
    const fs::path dir = freshDir("plot_bad");
    const std::string path = (dir / "study.png").string();
    vdbio::writePlotPng(path, twoSeries());
    const std::string before = slurp(path);

    PlotSpec empty = twoSeries();
    empty.points.clear();
    EXPECT_TRUE(
        contains(errorOf<ValueError>([&] { vdbio::writePlotPng(path, empty); }), "no points"));

    PlotSpec tiny = twoSeries();
    tiny.width = 10;
    EXPECT_TRUE(
        contains(errorOf<ValueError>([&] { vdbio::writePlotPng(path, tiny); }), "width = 10"));

    PlotSpec notFinite = twoSeries();
    notFinite.points[1].y = std::numeric_limits<double>::infinity();
    const std::string text = errorOf<ValueError>([&] { vdbio::writePlotPng(path, notFinite); });
    EXPECT_TRUE(contains(text, "'h=0.02'") && contains(text, "finite")) << text;

    // An unlabelled point is named by its index.
    PlotSpec unlabelled = twoSeries();
    unlabelled.points[3].label.clear();
    unlabelled.points[3].x = 0.0;
    EXPECT_TRUE(
        contains(errorOf<ValueError>([&] { vdbio::writePlotPng(path, unlabelled); }), "point #3"));

    EXPECT_TRUE(contains(errorOf<ValueError>([&] {
                             vdbio::writePlotPng((dir / "study.jpg").string(), twoSeries());
                         }),
                         ".png"));

    EXPECT_EQ(slurp(path), before);
    EXPECT_EQ(fileCount(dir), 1u);
}
