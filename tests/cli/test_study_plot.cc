/// @file   test_study_plot.cc
/// @brief  The study plot: the Pareto front (computed in C++), the points file, and the
///         matplotlib script that draws it (scripts/plot_study.py) with its errors.
#include "StudyPlot.h"

#include "common/Expect.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>

using namespace ghostfx;
using cmd::PlotPoint;
using ghostfx::testing::contains;
using ghostfx::testing::slurp;
namespace fs = std::filesystem;

TEST(StudyParetoFront, HandMadeSetGivesExactlyTheUnbeatenPointsSortedByX)
{
    const std::vector<PlotPoint> points = {{1.0, 10.0, "", "a"},  // front
                                           {2.0, 5.0, "", "b"},   // front
                                           {3.0, 6.0, "", "c"},   // beaten by b in x and y
                                           {2.0, 7.0, "", "d"},   // same x as b, larger y
                                           {4.0, 1.0, "", "e"},   // front
                                           {5.0, 1.0, "", "f"},   // same y as e, larger x
                                           {0.5, 20.0, "", "g"}}; // front: cheapest
    EXPECT_EQ(cmd::paretoFront(points), (std::vector<std::size_t>{6, 0, 1, 4}));
}

TEST(StudyParetoFront, TiesSinglePointAndNonFiniteValues)
{
    // Identical points beat neither each other: both on the front, or both off it.
    EXPECT_EQ(cmd::paretoFront({{1, 1, "", ""}, {2, 0.5, "", ""}, {1, 1, "", ""}}),
              (std::vector<std::size_t>{0, 2, 1}));
    EXPECT_EQ(cmd::paretoFront({{2, 2, "", ""}, {1, 1, "", ""}, {2, 2, "", ""}}),
              (std::vector<std::size_t>{1}));
    EXPECT_EQ(cmd::paretoFront({{3, 4, "", ""}}), (std::vector<std::size_t>{0}));
    EXPECT_TRUE(cmd::paretoFront({}).empty());
    // A NaN point is never on the front and beats nothing.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(cmd::paretoFront({{nan, 0.1, "", ""}, {2, 2, "", ""}}),
              (std::vector<std::size_t>{1}));
}

TEST(StudyPlot, PointsFileMarksTheFrontAndTheScriptDrawsIt)
{
    const fs::path dir = ghostfx::testing::freshDir("study_plot");
    const std::string points = (dir / "plot.csv").string();
    // A label with a comma and a quote survives the CSV both ways.
    cmd::writePlotPoints(points, "cpu_per_sim_second", "surge_front_error",
                         {{10, 0.1, "method=ghost", "h=0.02"},
                          {20, 0.2, "method=basic", "h=0.02, \"fine\""},
                          {40, 0.01, "method=ghost", "h=0.01"}});
    EXPECT_EQ(slurp(points), "series,label,cpu_per_sim_second,surge_front_error,pareto\n"
                             "method=ghost,h=0.02,10,0.10000000000000001,1\n"
                             "method=basic,\"h=0.02, \"\"fine\"\"\",20,0.20000000000000001,0\n"
                             "method=ghost,h=0.01,40,0.01,1\n");

    // The script, as `ghostfx study` runs it: a PNG (its signature) of matplotlib's size
    // (8 x 5.6 inches at 100 dpi), and no leftover log.
    const std::string image = (dir / "study.png").string();
    ASSERT_EQ(cmd::drawPlot(points, image, "dam break"), "");
    const std::string png = slurp(image);
    ASSERT_GT(png.size(), 24u);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    auto be32 = [&](std::size_t at) {
        return (unsigned(std::uint8_t(png[at])) << 24) | (unsigned(std::uint8_t(png[at + 1])) << 16)
               | (unsigned(std::uint8_t(png[at + 2])) << 8) | unsigned(std::uint8_t(png[at + 3]));
    };
    EXPECT_EQ(be32(16), 800u); // IHDR width
    EXPECT_EQ(be32(20), 560u); // IHDR height
    EXPECT_FALSE(fs::exists(points + ".log"));
    EXPECT_TRUE(contains(cmd::plotCommand(points, image, "dam break"), "plot_study.py"));

    // A non-positive error on a log axis: the script names the run and leaves the old image.
    cmd::writePlotPoints(points, "cpu_per_sim_second", "surge_front_error",
                         {{10, 0.0, "runs", "h=0.04"}});
    const std::string why = cmd::drawPlot(points, image, "");
    EXPECT_TRUE(contains(why, "run 'h=0.04' has cpu_per_sim_second = 10.0, surge_front_error = "
                              "0.0: a log axis needs values > 0"))
        << why;
    EXPECT_EQ(slurp(image), png);
    // No script where it is looked for: one line saying so, nothing thrown.
    ::setenv("GHOSTFX_PLOT_SCRIPT", (dir / "missing.py").string().c_str(), 1);
    EXPECT_TRUE(contains(cmd::drawPlot(points, image, ""), "missing.py"));
    ::unsetenv("GHOSTFX_PLOT_SCRIPT");
}
