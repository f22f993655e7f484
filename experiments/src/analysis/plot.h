#pragma once
// PNG line/point plots drawn with OpenCV (core, imgproc, imgcodecs): the figures
// an experiment writes next to its results.json (angle vs friction, profiles, ...).
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
};

struct PlotSpec {
  std::string title, x_label, y_label;  // labels carry units, e.g. "time (s)"
  std::vector<PlotSeries> series;       // coloured in order from a fixed colour-blind-safe palette
  // Axis ranges; default: the finite data range with a 5 % margin (a single value gets a span
  // of ±10 % of its magnitude, or ±0.5 when it is 0; no finite data gives [0, 1]).
  std::optional<std::pair<double, double>> x_range, y_range;
  int width = 900, height = 600;  // pixels; at least 200 × 150
};

/// Draws the plot and writes it as PNG atomically (to "<png>.partial", then rename), so a half-written
/// plot never replaces a good one. Throws std::runtime_error naming the file when it cannot write, and
/// std::invalid_argument when a series has x and y of different lengths or the size is too small.
void writePlot(const PlotSpec& spec, const std::filesystem::path& png);

}  // namespace rocklab::experiments
