// writePlot (plot.h): the checks, the data as CSV, then gnuplot or the built-in plotter.
#include "analysis/plot.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "analysis/plot_internal.h"
#include "common/atomic_file.h"
#include "common/csv.h"

namespace rocklab::experiments {

namespace detail {

bool drawable(const PlotSpec& spec, double x, double y) {
  return std::isfinite(x) && std::isfinite(y) && (!spec.log_x || x > 0) && (!spec.log_y || y > 0);
}

AxisRange axisRange(const PlotSpec& spec, bool x_axis) {
  const bool log_axis = x_axis ? spec.log_x : spec.log_y;
  const auto& fixed = x_axis ? spec.x_range : spec.y_range;
  if (fixed) {
    if (!std::isfinite(fixed->first) || !std::isfinite(fixed->second) || !(fixed->first < fixed->second) ||
        (log_axis && !(fixed->first > 0)))
      throw std::invalid_argument("plot '" + spec.title + "': the " + (x_axis ? "x" : "y") +
                                  " range must be finite with lo < hi" + (log_axis ? " and lo > 0 (a log axis)" : ""));
    return {fixed->first, fixed->second};
  }
  double lo = INFINITY, hi = -INFINITY;
  for (const PlotSeries& s : spec.series)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (drawable(spec, s.x[i], s.y[i])) {
        const double v = x_axis ? s.x[i] : s.y[i];
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  if (log_axis) {  // the same rules on log10 of the values
    if (lo > hi) return {1.0, 10.0};
    if (hi <= lo * (1 + 1e-12)) return {lo / 2, hi * 2};
    const double margin = std::pow(hi / lo, 0.05);
    return {lo / margin, hi * margin};
  }
  if (lo > hi) return {0.0, 1.0};  // no finite data
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {
    const double half = lo == 0.0 ? 0.5 : 0.1 * std::abs(lo);
    return {lo - half, hi + half};
  }
  const double margin = 0.05 * (hi - lo);
  return {lo - margin, hi + margin};
}

std::string gnuplotProgram() {
  if (const char* set = std::getenv("ROCKLAB_GNUPLOT"); set != nullptr && *set != '\0')
    return std::string(set) == "none" ? "" : set;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    if (!dir.empty() && ::access((dir + "/gnuplot").c_str(), X_OK) == 0) return dir + "/gnuplot";
  return "";
}

}  // namespace detail

namespace {

/// The plotted data, one row a point: series (its legend text, else its number), x, y.
std::string plotCsv(const PlotSpec& spec) {
  std::string csv = "series," + detail::csvCell(spec.x_label.empty() ? "x" : spec.x_label) + "," +
                    detail::csvCell(spec.y_label.empty() ? "y" : spec.y_label) + "\n";
  char number[64];
  for (std::size_t k = 0; k < spec.series.size(); ++k) {
    const PlotSeries& s = spec.series[k];
    const std::string name = detail::csvCell(!s.data_name.empty() ? s.data_name
                                     : s.label.empty()    ? "series " + std::to_string(k + 1)
                                                          : s.label);
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      std::snprintf(number, sizeof number, ",%.10g,%.10g\n", s.x[i], s.y[i]);
      csv += name + number;
    }
  }
  return csv;
}

}  // namespace

std::filesystem::path plotDataPath(const std::filesystem::path& png) {
  std::filesystem::path csv = png;
  return csv.replace_extension(".plot.csv");
}

PlotSpec sieveChart(std::string title) {
  PlotSpec spec;
  spec.title = std::move(title);
  spec.x_label = "sieve size (mm)";
  spec.y_label = "cumulative mass passing (%)";
  spec.log_x = true;
  spec.y_range = std::pair{0.0, 100.0};
  return spec;
}

void writePlot(const PlotSpec& spec, const std::filesystem::path& png) { writePlotRow({spec}, png); }

void writePlotRow(const std::vector<PlotSpec>& panels, const std::filesystem::path& png) {
  if (panels.empty()) throw std::invalid_argument("plot '" + png.string() + "': no panel to draw");
  for (const PlotSpec& spec : panels) {
    if (spec.width < 200 || spec.height < 150)
      throw std::invalid_argument("plot '" + png.string() + "': size must be at least 200 x 150 pixels");
    for (const PlotSeries& s : spec.series)
      if (s.x.size() != s.y.size())
        throw std::invalid_argument("plot '" + png.string() + "': series '" + s.label + "' has " +
                                    std::to_string(s.x.size()) + " x values but " + std::to_string(s.y.size()) +
                                    " y values");
    detail::axisRange(spec, true);  // a bad fixed range is refused before anything is written
    detail::axisRange(spec, false);
  }

  if (const std::string gnuplot = detail::gnuplotProgram(); !gnuplot.empty()) {
    detail::drawPlotWithGnuplot(panels, png, gnuplot);
  } else {
    static std::once_flag said;
    std::call_once(said, [] {
      std::cerr << "rocklab: gnuplot not found (Debian: gnuplot-nox): plots are drawn as PNG only, by the built-in "
                   "plotter (no SVG; a log axis shows log10 of the values)\n";
    });
    detail::drawPlotWithOpenCv(panels, png);
  }
  // The plotted data, after the plot (an error names the plot first): the panels'
  // series one after the other, named by their panel when there are several.
  PlotSpec data = panels.front();
  if (panels.size() > 1) {
    data.series.clear();
    for (const PlotSpec& panel : panels)
      for (std::size_t k = 0; k < panel.series.size(); ++k) {
        PlotSeries s = panel.series[k];
        const std::string name = !s.data_name.empty() ? s.data_name
                                 : s.label.empty()    ? "series " + std::to_string(k + 1)
                                                      : s.label;
        s.data_name = panel.title + ": " + name;
        data.series.push_back(std::move(s));
      }
  }
  detail::writeAtomically(plotDataPath(png), plotCsv(data));
}

}  // namespace rocklab::experiments
