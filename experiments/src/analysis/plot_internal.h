#pragma once
// The two ways writePlot (plot.h) draws: gnuplot (PNG + SVG), or, when gnuplot is
// not installed, the built-in OpenCV plotter (PNG only). Both take their axis
// ranges from axisRange, so a plot covers the same data either way. Internal.
#include <filesystem>
#include <string>
#include <vector>

#include "analysis/plot.h"

namespace rocklab::experiments::detail {

struct AxisRange {
  double lo, hi;
};

/// The axis range: the spec's fixed one, or the finite data range with a 5 % margin
/// (on a log axis: the positive data, the margin a factor); degenerate data as plot.h says.
AxisRange axisRange(const PlotSpec& spec, bool x_axis);

/// Whether a point is drawn: both coordinates finite, and positive on a log axis.
bool drawable(const PlotSpec& spec, double x, double y);

/// The gnuplot program: $ROCKLAB_GNUPLOT when set ("none": there is none), else
/// "gnuplot" when it is on the PATH; "" when there is none.
std::string gnuplotProgram();

/// Draws the panels side by side with gnuplot: png and the SVG beside it, each written
/// to "<file>.partial" and renamed. Throws std::runtime_error naming the plot and
/// gnuplot's message when it fails.
void drawPlotWithGnuplot(const std::vector<PlotSpec>& panels, const std::filesystem::path& png,
                         const std::string& program);

/// Draws the panels side by side with OpenCV: png only (atomically); log axes as log10
/// of the values.
void drawPlotWithOpenCv(const std::vector<PlotSpec>& panels, const std::filesystem::path& png);

}  // namespace rocklab::experiments::detail
