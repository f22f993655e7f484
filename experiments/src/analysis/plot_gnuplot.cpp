// writePlot's gnuplot drawing (plot_internal.h): one script (data inline), run as
// a child process; PNG by pngcairo and SVG from the same commands (panels side by
// side as a multiplot).
#include <algorithm>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "analysis/plot_internal.h"
#include "common/atomic_file.h"

extern char** environ;

namespace rocklab::experiments::detail {

namespace fs = std::filesystem;

namespace {

// Okabe–Ito colour-blind-safe palette (the built-in plotter's); its yellow is left out.
constexpr std::array<const char*, 7> kPalette = {"#0072B2", "#D55E00", "#009E73", "#E69F00",
                                                 "#CC79A7", "#56B4E9", "#000000"};

/// A gnuplot double-quoted string (backslash and quote escaped; line breaks as spaces).
std::string quoted(const std::string& text) {
  std::string q = "\"";
  for (const char c : text) {
    if (c == '\\' || c == '"') q += '\\';
    q += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return q + "\"";
}

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string withStyle(PlotSeries::Style style) {
  switch (style) {
    case PlotSeries::Style::Line: return "with lines lw 2";
    case PlotSeries::Style::Points: return "with points pt 7 ps 0.9";
    case PlotSeries::Style::LinePoints: break;
  }
  return "with linespoints lw 2 pt 7 ps 0.9";
}

/// One panel's data blocks (named "$<prefix><k>") and the commands that draw it; the
/// commands set everything a panel uses, so panels of a multiplot do not inherit.
struct PanelScript {
  std::string data, commands;
};

PanelScript panelScript(const PlotSpec& spec, const std::string& prefix) {
  PanelScript out;
  std::string plot;
  for (std::size_t k = 0; k < spec.series.size(); ++k) {
    const PlotSeries& series = spec.series[k];
    std::string data;
    bool any = false, gap = false;
    for (std::size_t i = 0; i < series.x.size(); ++i) {
      if (!drawable(spec, series.x[i], series.y[i])) {  // a blank line breaks the line there
        gap = any;
        continue;
      }
      if (gap) data += "\n";
      gap = false;
      any = true;
      data += number(series.x[i]) + " " + number(series.y[i]) + "\n";
    }
    if (!any) continue;  // gnuplot refuses a data block without points
    const std::string block = "$" + prefix + std::to_string(k);
    out.data += block + " << EOD\n" + data + "EOD\n";
    plot += std::string(plot.empty() ? "plot " : ", ") + block + " using 1:2 " + withStyle(series.style) +
            " lc rgb '" + kPalette[colourIndexOf(series, k) % kPalette.size()] + "' " +
            (series.label.empty() ? std::string("notitle") : "title " + quoted(series.label));
  }
  if (plot.empty()) plot = "plot NaN notitle";  // axes only
  const AxisRange xr = axisRange(spec, true), yr = axisRange(spec, false);
  std::string& s = out.commands;
  s += "set title " + quoted(spec.title) + "\nset xlabel " + quoted(spec.x_label) + "\nset ylabel " +
       quoted(spec.y_label) + "\n";
  s += "set xrange [" + number(xr.lo) + ":" + number(xr.hi) + "]\nset yrange [" + number(yr.lo) + ":" +
       number(yr.hi) + "]\n";
  s += "unset logscale\n";
  if (spec.log_x) s += "set logscale x\n";
  if (spec.log_y) s += "set logscale y\n";
  s += "set grid lc rgb '#e4e4e4' lt 1\nset border lc rgb '#1e1e1e'\n";
  // The key above the axes (inside them an opaque key hid the data points under it),
  // two characters wider than gnuplot reckons (pngcairo's labels overran its box);
  // none when no series has a label (an empty box otherwise).
  s += (std::any_of(spec.series.begin(), spec.series.end(), [](const PlotSeries& p) { return !p.label.empty(); })
            ? "set key outside top center horizontal box width 2\n"
            : "unset key\n");
  s += plot + "\n";
  return out;
}

/// The script for panels side by side (one panel: a plain plot), drawn once as PNG
/// and once as SVG.
std::string script(const std::vector<PlotSpec>& panels, const fs::path& png_partial, const fs::path& svg_partial) {
  std::string s = "set encoding utf8\n";  // noenhanced on each terminal: labels are text, not markup
  std::string body;
  int width = 0, height = 0;
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const PanelScript panel = panelScript(panels[p], "p" + std::to_string(p) + "s");
    s += panel.data;
    body += panel.commands;
    width += panels[p].width;
    height = std::max(height, panels[p].height);
  }
  if (panels.size() > 1) body = "set multiplot layout 1," + std::to_string(panels.size()) + "\n" + body + "unset multiplot\n";
  const std::string size = std::to_string(width) + "," + std::to_string(height);
  s += "set terminal pngcairo noenhanced size " + size + " background rgb 'white' font 'sans,10'\nset output " +
       quoted(png_partial.string()) + "\n" + body;
  s += "set terminal svg noenhanced size " + size + " dynamic background rgb 'white' font 'sans,12'\nset output " +
       quoted(svg_partial.string()) + "\n" + body + "unset output\n";
  return s;
}

/// A scratch file of this process (two plots at once get two).
fs::path scratch(const std::string& suffix) {
  static std::atomic<unsigned> counter{0};
  return fs::temp_directory_path() /
         ("rocklab-plot-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + suffix);
}

/// Runs `program script` with its output in `said`; returns its wait status, or -1 when it could not start.
int runGnuplot(const std::string& program, const fs::path& script_file, const fs::path& said) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, said.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const std::string script_arg = script_file.string();
  char* const argv[] = {const_cast<char*>(program.c_str()), const_cast<char*>(script_arg.c_str()), nullptr};
  pid_t child = 0;
  const int started = posix_spawnp(&child, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (started != 0) return -1;
  int status = 0;
  while (::waitpid(child, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return status;
}

}  // namespace

void drawPlotWithGnuplot(const std::vector<PlotSpec>& panels, const fs::path& png, const std::string& program) {
  fs::path svg = png;
  svg.replace_extension(".svg");
  const fs::path png_partial = png.string() + ".partial", svg_partial = svg.string() + ".partial";
  const fs::path script_file = scratch(".gp"), said = scratch(".txt");
  writeAtomically(script_file, script(panels, png_partial, svg_partial));
  const int status = runGnuplot(program, script_file, said);
  std::ifstream in(said);
  std::string message{std::istreambuf_iterator<char>(in), {}};
  std::error_code ec;
  fs::remove(script_file, ec);
  fs::remove(said, ec);
  if (status != 0 || !fs::exists(png_partial, ec) || !fs::exists(svg_partial, ec)) {
    fs::remove(png_partial, ec);
    fs::remove(svg_partial, ec);
    if (message.size() > 600) message = message.substr(0, 600) + "...";
    throw std::runtime_error("plot '" + png.string() + "': gnuplot (" + program + ") " +
                             (status < 0 ? "could not be started" : "failed") +
                             (message.empty() ? std::string() : ": " + message));
  }
  for (const auto& [from, to] : {std::pair{png_partial, png}, std::pair{svg_partial, svg}}) {
    fs::rename(from, to, ec);
    if (ec) throw std::runtime_error("plot '" + to.string() + "': cannot rename " + from.string() + ": " + ec.message());
  }
}

}  // namespace rocklab::experiments::detail
