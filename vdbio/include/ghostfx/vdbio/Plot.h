/// @file   Plot.h
/// @brief  Error-versus-cost scatter plots written as PNG, with the Pareto front marked.
/// @details Made for `ghostfx study`, which runs one scene over a sweep of settings and wants to
///          show which settings are worth their cost. Each point is one run (x = cost, y = error,
///          both minimised); points are grouped into series (one colour each, listed in a legend
///          to the right of the plot). The Pareto front, the runs that no other run beats in both
///          cost and error, is drawn as a dark line through its points sorted by cost, and its
///          markers are ringed and labelled.
///
///          Rendering needs no font files or extra libraries: text uses a built-in 5x7 bitmap
///          font (printable ASCII) drawn at an integer scale that grows with the image size. Log
///          axes carry labelled ticks at decades ("1e-3", "0.01", ..., "100", "1e4") and
///          unlabelled ticks at 2 and 5 where there is room; linear axes use 1-2-5 steps. The data
///          range is padded so that no marker touches the axes box. The image is written
///          atomically (writeAtomically) as an 8-bit sRGB PNG.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// One run of a study: its cost and error, the series it belongs to and a short label.
struct PlotPoint
{
    /// Horizontal coordinate (a cost: seconds, particle count...); > 0 on a log x axis.
    double x = 0;
    /// Vertical coordinate (an error); > 0 on a log y axis.
    double y = 0;
    /// Series name: points with the same name share a colour and a legend entry.
    std::string series;
    /// Short text naming the point ("h=0.02"): drawn beside Pareto-front points and used in
    /// error messages.
    std::string label;
};

/// What to plot and how. writePlotPng() checks every field.
struct PlotSpec
{
    /// Title above the plot and the axis labels; each may be empty (then it is not drawn).
    std::string title, xLabel, yLabel;
    /// Logarithmic axes (base 10): every value on a log axis must be > 0.
    bool logX = true, logY = true;
    /// Image size (pixels): width in [MIN_WIDTH, MAX_SIDE], height in [MIN_HEIGHT, MAX_SIDE].
    int width = 800, height = 560;
    /// The points, at least one; every coordinate finite.
    std::vector<PlotPoint> points;
    /// Draw the Pareto front (minimise x and y): a dark line through its points sorted by x,
    /// ringed markers and the points' labels.
    bool markPareto = true;

    static constexpr int MIN_WIDTH = 240, MIN_HEIGHT = 180, MAX_SIDE = 8192;
};

/// Indices of the points on the Pareto front of (x, y), both minimised, sorted by x (then y, then
/// index). A point is on the front when no other point has x <= and y <= with at least one of
/// them strictly smaller; identical points therefore are all on the front or all off it. Points
/// with a non-finite coordinate are never on the front and beat no other point.
std::vector<std::size_t> paretoFront(const std::vector<PlotPoint>& points);

/// Render `spec` and write it atomically to `path`, which must end in ".png". Throws ValueError
/// (ghostfx/sph/Exceptions.h) for no points, a non-finite coordinate, a value <= 0 on a log axis
/// (the message names the point's label, or its index when the label is empty, and the value)
/// or a size out of range, before anything is written; IoError if the file cannot be written.
void writePlotPng(const std::string& path, const PlotSpec& spec);

/// Pixel {column, row from the top} at which writePlotPng() centres the marker of a point at
/// data coordinates (x, y) in the image of `spec` (the same layout and axis mapping). For tests
/// and for callers that annotate the image. Throws ValueError as writePlotPng() does.
std::array<int, 2> plotPixelOf(const PlotSpec& spec, double x, double y);

/// The sRGB colour (8 bits per channel) of a series; series are numbered in the order their
/// names first appear in PlotSpec::points, and the palette of 8 colours repeats after the 8th.
std::array<std::uint8_t, 3> plotSeriesColour(std::size_t seriesIndex);

} // namespace vdbio
} // namespace ghostfx
