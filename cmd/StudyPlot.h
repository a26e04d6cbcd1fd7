/// @file   StudyPlot.h
/// @brief  A study's error-versus-cost plot: the points and their Pareto front, computed here,
///         drawn by a matplotlib script (scripts/plot_study.py) that users can edit and rerun.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace ghostfx {
namespace cmd {

/// One run of a study: its cost and error, the series it belongs to and a short label.
struct PlotPoint
{
    double x = 0;       ///< cost (seconds, particles, ...); > 0 on the log axis
    double y = 0;       ///< error; > 0 on the log axis
    std::string series; ///< points with the same series share a colour and a legend entry
    std::string label;  ///< short text naming the run ("h=0.02"), shown beside front points
};

/// Indices of the points on the Pareto front of (x, y), both minimised, sorted by x (then y, then
/// index). A point is on the front when no other point has x <= and y <= with at least one of
/// them strictly smaller; identical points therefore are all on the front or all off it. Points
/// with a non-finite coordinate are never on the front and beat no other point.
std::vector<std::size_t> paretoFront(const std::vector<PlotPoint>& points);

/// Write the points as `series,label,<xName>,<yName>,pareto` rows (CSV, quoted where a field
/// needs it; pareto 1 for the front), atomically.
void writePlotPoints(const std::string& path, const std::string& xName, const std::string& yName,
                     const std::vector<PlotPoint>& points);

/// The plotting script: $GHOSTFX_PLOT_SCRIPT, else share/ghostfx/plot_study.py beside an
/// installed program, else the source tree's scripts/plot_study.py; "" if none exists.
std::string plotScript();

/// The command line that draws `points` (a file from writePlotPoints) into `image`, as a user
/// would type it to redraw after editing the script.
std::string plotCommand(const std::string& points, const std::string& image,
                        const std::string& title);

/// Draw the plot with the script ($GHOSTFX_PYTHON or the configured python3). Returns "" when
/// the image was written, else one line saying why not (no script, no matplotlib, ...).
std::string drawPlot(const std::string& points, const std::string& image, const std::string& title);

} // namespace cmd
} // namespace ghostfx
