#pragma once
// Line/point plots: the figures an experiment, sweep or study writes next to its
// results (angle vs friction, profiles, force-displacement, Weibull, ...). Drawn by
// gnuplot (Debian gnuplot-nox) as PNG and SVG, the plotted data as CSV beside them;
// without gnuplot, by the built-in OpenCV plotter as PNG only (plot_internal.h).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rocklab::experiments {

struct PlotSeries {
  std::string label;         // legend text ("" = not in the legend)
  std::vector<double> x, y;  // same length; non-finite points are skipped (a line breaks there)
  enum class Style { Line, Points, LinePoints } style = Style::LinePoints;
  // Index into the palette; -1: the series' own index. Curves of one group share one
  // colour (a crushing batch: one colour per r0, one legend entry per group).
  int colour = -1;
  // Its name in the plotted data (plotDataPath): "" = the label, or "series K" without one.
  std::string data_name = "";
};

/// The palette index a series is drawn with (its `colour`, else its index `k`).
inline std::size_t colourIndexOf(const PlotSeries& s, std::size_t k) {
  return s.colour >= 0 ? static_cast<std::size_t>(s.colour) : k;
}

struct PlotSpec {
  std::string title, x_label, y_label;  // labels carry units, e.g. "time (s)"
  std::vector<PlotSeries> series;       // coloured in order from a fixed colour-blind-safe palette
  // Axis ranges; default: the finite data range with a 5 % margin (a single value gets a span
  // of ±10 % of its magnitude, or ±0.5 when it is 0; no finite data gives [0, 1]).
  std::optional<std::pair<double, double>> x_range, y_range;
  // Logarithmic axes (product curves, Weibull plots): points <= 0 on them are skipped
  // like non-finite ones; a fixed range must then be positive.
  bool log_x = false, log_y = false;
  int width = 900, height = 600;  // pixels; at least 200 × 150
};

/// A sieve chart's frame: cumulative mass passing (%, 0-100) against the sieve size
/// (mm, log axis), as product curves are drawn.
PlotSpec sieveChart(std::string title);

/// Draws the plot: `png`, the SVG beside it (same stem; with gnuplot only) and the
/// plotted data as plotDataPath(png), each written atomically ("<file>.partial", then
/// rename), so a half-written plot never replaces a good one. Throws std::runtime_error
/// naming the file when it cannot write or gnuplot fails, and std::invalid_argument when
/// a series has x and y of different lengths, the size is too small or a fixed range is bad.
void writePlot(const PlotSpec& spec, const std::filesystem::path& png);

/// Panels side by side in one figure (a velocity profile a zone), each drawn as
/// writePlot draws it at its own width and height; the same files and errors. In the
/// plotted data a point's series is "PANEL TITLE: SERIES" when there is more than one panel.
void writePlotRow(const std::vector<PlotSpec>& panels, const std::filesystem::path& png);

/// "<stem>.plot.csv" beside the PNG: series, x, y, one row a point, as given (non-finite too).
std::filesystem::path plotDataPath(const std::filesystem::path& png);

}  // namespace rocklab::experiments
