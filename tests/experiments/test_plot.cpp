// Plots: drawn at the asked size with the series colours (gnuplot, or the built-in
// plotter without it), SVG and data beside the PNG, log axes, written atomically,
// errors name the file, degenerate data does not crash.
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "analysis/plot.h"
#include "analysis/plot_internal.h"
#include "analysis/sweep_table.h"
#include "common/csv.h"

using namespace rocklab::experiments;
using Catch::Contains;
using Catch::StartsWith;
namespace fs = std::filesystem;

namespace {
/// A fresh directory under the system temp directory.
fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rocklab-plot-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// Pixels of exactly this BGR colour.
int countColour(const cv::Mat& img, cv::Vec3b bgr) {
  int n = 0;
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) n += img.at<cv::Vec3b>(r, c) == bgr;
  return n;
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

TEST_CASE("a plot with two series and NaNs is drawn and written", "[plot]") {
  const fs::path dir = tempDir("two");
  PlotSpec spec;
  spec.title = "angle of repose vs friction";
  spec.x_label = "friction coefficient (-)";
  spec.y_label = "angle of repose (deg)";
  PlotSeries dem{"DEM", {}, {}, PlotSeries::Style::LinePoints};
  for (int i = 0; i <= 10; ++i) {
    dem.x.push_back(0.1 * i);
    dem.y.push_back(i == 4 ? kNaN : 15.0 + 20.0 * std::sqrt(0.1 * i));  // a gap in the line
  }
  const PlotSeries lab{"lab mean", {0.0, 1.0, kNaN}, {26.03, 26.03, 3.0}, PlotSeries::Style::Line};
  spec.series = {dem, lab};
  const fs::path png = dir / "repose.png";
  writePlot(spec, png);

  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  REQUIRE(!img.empty());
  CHECK(img.cols == 900);
  CHECK(img.rows == 600);
  const int non_white = img.rows * img.cols - countColour(img, {255, 255, 255});
  CHECK(non_white > 5000);
  CHECK(countColour(img, {178, 114, 0}) > 100);  // palette colour 0 (blue): points and line
  CHECK(countColour(img, {0, 94, 213}) > 100);   // palette colour 1 (vermillion): line
  CHECK(!fs::exists(dir / "repose.png.partial"));

  // Writing again replaces the plot, and leaves no .partial either.
  spec.width = 400;
  spec.height = 300;
  writePlot(spec, png);
  CHECK(cv::imread(png.string()).cols == 400);
  CHECK(!fs::exists(dir / "repose.png.partial"));
}

TEST_CASE("an unwritable plot path throws and names the file", "[plot]") {
  PlotSpec spec;
  spec.series = {{"s", {0, 1}, {0, 1}}};
  const std::string path = "/proc/rocklab-no-such-dir/plot.png";
  try {
    writePlot(spec, path);
    FAIL("no error");
  } catch (const std::runtime_error& e) {
    CHECK_THAT(e.what(), Contains(path));
  }
  PlotSeries bad{"uneven", {0, 1, 2}, {0, 1}};
  spec.series = {bad};
  CHECK_THROWS_WITH(writePlot(spec, tempDir("bad") / "p.png"), Contains("uneven") && Contains("3 x values"));
}

TEST_CASE("degenerate data: constant - single point - no finite data", "[plot]") {
  const fs::path dir = tempDir("degenerate");
  PlotSpec spec;
  spec.series = {{"constant", {0, 1, 2, 3}, {2.5, 2.5, 2.5, 2.5}}};
  CHECK_NOTHROW(writePlot(spec, dir / "constant.png"));
  spec.series = {{"one point", {7.0}, {0.0}, PlotSeries::Style::Points}};
  CHECK_NOTHROW(writePlot(spec, dir / "point.png"));
  spec.series = {{"", {kNaN, 1.0}, {kNaN, kNaN}}, {}};
  CHECK_NOTHROW(writePlot(spec, dir / "nothing.png"));
  spec.series = {{"huge", {0, 1}, {-1e300, 1e300}}};
  spec.y_range = std::pair{-1.0, 1.0};  // points far outside the fixed range are clipped
  CHECK_NOTHROW(writePlot(spec, dir / "clipped.png"));
  for (const char* name : {"constant.png", "point.png", "nothing.png", "clipped.png"})
    CHECK(cv::imread((dir / name).string()).cols == 900);
}

namespace {
/// Runs `command` through the shell; its exit code.
int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
/// Sets an environment variable for one scope.
struct ScopedEnv {
  ScopedEnv(const char* name, const char* value) : name_(name) { ::setenv(name, value, 1); }
  ~ScopedEnv() { ::unsetenv(name_); }
  const char* name_;
};
std::string slurpText(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), {}};
}
}  // namespace

TEST_CASE("gnuplot draws PNG and SVG with the data beside them - log axes skip points <= 0", "[plot]") {
  if (rocklab::experiments::detail::gnuplotProgram().empty())
    FAIL("gnuplot is not installed (scripts/setup.sh installs gnuplot-nox)");
  const fs::path dir = tempDir("gnuplot");
  PlotSpec spec;
  spec.title = "passing \"fraction\" & size <log-log>";
  spec.x_label = "size (m)";
  spec.y_label = "passing (%)";
  spec.log_x = spec.log_y = true;
  spec.series = {{"product, run 1", {0.001, 0.01, 0.1, 0.0, 1.0}, {0.01, 0.1, 10.0, 5.0, 100.0}},
                 {"lab", {0.002, 0.02}, {-1.0, 1.0}, PlotSeries::Style::Points}};
  writePlot(spec, dir / "curve.png");
  const cv::Mat img = cv::imread((dir / "curve.png").string(), cv::IMREAD_COLOR);
  REQUIRE(!img.empty());
  CHECK(img.cols == 900);
  CHECK(countColour(img, {178, 114, 0}) > 100);  // palette colour 0 (#0072B2), as the built-in plotter's
  const std::string svg = slurpText(dir / "curve.svg");
  CHECK_THAT(svg, Contains("<svg"));
  CHECK(shell("xmllint --noout '" + (dir / "curve.svg").string() + "'") == 0);  // well-formed, title escaped
  CHECK_THAT(svg, Contains("> 0.01<") && Contains("> 0.001<"));  // decade ticks of the log axes
  CHECK_THAT(svg, Contains("passing \"fraction\" &amp; size &lt;log-log>"));  // the title as given
  const std::string csv = slurpText(dir / "curve.plot.csv");
  CHECK_THAT(csv, StartsWith("series,size (m),passing (%)\n"));
  CHECK_THAT(csv, Contains("\"product, run 1\",0.001,0.01\n") && Contains("lab,0.002,-1\n"));
  for (const char* left : {"curve.png.partial", "curve.svg.partial", "curve.plot.csv.partial"})
    CHECK_FALSE(fs::exists(dir / left));
  spec.y_range = std::pair{0.0, 10.0};  // a log axis cannot start at 0
  CHECK_THROWS_WITH(writePlot(spec, dir / "bad.png"), Contains("lo > 0"));
}

TEST_CASE("without gnuplot the built-in plotter draws the PNG (no SVG) - a failing gnuplot names the plot", "[plot]") {
  const fs::path dir = tempDir("fallback");
  PlotSpec spec;
  spec.series = {{"s", {1, 10, 100}, {1, 2, 3}}};
  spec.log_x = true;
  {
    const ScopedEnv none("ROCKLAB_GNUPLOT", "none");
    writePlot(spec, dir / "p.png");
  }
  CHECK(cv::imread((dir / "p.png").string()).cols == 900);
  CHECK_FALSE(fs::exists(dir / "p.svg"));
  CHECK(fs::exists(dir / "p.plot.csv"));
  const ScopedEnv failing("ROCKLAB_GNUPLOT", "false");  // exits 1 at once
  CHECK_THROWS_WITH(writePlot(spec, dir / "q.png"), Contains((dir / "q.png").string()) && Contains("gnuplot (false) failed"));
  CHECK_FALSE(fs::exists(dir / "q.png"));
  CHECK_FALSE(fs::exists(dir / "q.png.partial"));
}

TEST_CASE("CSV cells: a comma, a quote or a line break stays in its cell, written and read back", "[plot][csv]") {
  using rocklab::experiments::detail::csvCell;
  using rocklab::experiments::detail::splitCsvLine;
  const std::vector<std::string> cells{"[0,0,0.05]", "plain", "", "say \"hi\", then go", "exit 3: a, b", "0.5", ""};
  std::string line;
  for (std::size_t k = 0; k < cells.size(); ++k) line += (k ? "," : "") + csvCell(cells[k]);
  CHECK(line == "\"[0,0,0.05]\",plain,,\"say \"\"hi\"\", then go\",\"exit 3: a, b\",0.5,");
  CHECK(splitCsvLine(line) == cells);
  CHECK(splitCsvLine("a,b") == std::vector<std::string>{"a", "b"});
  // A sweep table with a vary value that holds commas is read back one cell a value.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "rocklab-csv-cells";
  std::filesystem::create_directories(dir);
  {
    std::ofstream csv(dir / "sweep.csv");
    csv << "walls.top.corner,clearance_time_s,status\n" << csvCell("[0,0,0.04]") << ",2.5,ok\n";
  }
  const auto table = rocklab::experiments::readSweepTable(dir);
  REQUIRE(table.rows.size() == 1);
  CHECK(table.rows[0] == std::vector<std::string>{"[0,0,0.04]", "2.5", "ok"});
  std::filesystem::remove_all(dir);
}

TEST_CASE("panels side by side: one image as wide as the panels, each panel's own range, the data named by panel", "[plot]") {
  const fs::path dir = tempDir("row");
  PlotSpec left, right;
  left.title = "zone 1";
  right.title = "zone 2";
  left.x_label = right.x_label = "velocity (m/s)";
  left.y_label = right.y_label = "height (mm)";
  left.width = right.width = 400;
  left.height = 300;
  right.height = 250;  // the shorter panel is padded to the row's height
  left.series = {{"inclined", {0.3, 0.35}, {10, 70}}};
  right.series = {{"inclined", {0.15, 0.2}, {20, 120}}, {"vertical", {0.14, 0.21}, {15, 110}}};
  right.series[1].colour = 1;
  for (const bool gnuplot : {true, false}) {
    if (gnuplot && rocklab::experiments::detail::gnuplotProgram().empty())
      FAIL("gnuplot is not installed (scripts/setup.sh installs gnuplot-nox)");
    const fs::path png = dir / (gnuplot ? "row.png" : "row-builtin.png");
    {
      std::unique_ptr<ScopedEnv> none;
      if (!gnuplot) none = std::make_unique<ScopedEnv>("ROCKLAB_GNUPLOT", "none");
      writePlotRow({left, right}, png);
    }
    const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
    REQUIRE(!img.empty());
    CHECK(img.cols == 800);
    CHECK(img.rows == 300);
    // Both panels are drawn: palette colour 0 in each half, colour 1 only in the right one.
    CHECK(countColour(img(cv::Rect(0, 0, 400, 300)), {178, 114, 0}) > 20);
    CHECK(countColour(img(cv::Rect(400, 0, 400, 300)), {178, 114, 0}) > 20);
    CHECK(countColour(img(cv::Rect(0, 0, 400, 300)), {0, 94, 213}) == 0);
    CHECK(countColour(img(cv::Rect(400, 0, 400, 300)), {0, 94, 213}) > 20);
    CHECK(fs::exists(dir / (gnuplot ? "row.svg" : "row-builtin.svg")) == gnuplot);
    const std::string csv = slurpText(plotDataPath(png));
    CHECK_THAT(csv, StartsWith("series,velocity (m/s),height (mm)\n"));
    CHECK_THAT(csv, Contains("zone 1: inclined,0.3,10\n") && Contains("zone 2: inclined,0.15,20\n") &&
                        Contains("zone 2: vertical,0.21,110\n"));
  }
  CHECK_THROWS_WITH(writePlotRow({}, dir / "none.png"), Contains("no panel"));
  right.width = 100;
  CHECK_THROWS_WITH(writePlotRow({left, right}, dir / "small.png"), Contains("at least 200 x 150"));
  CHECK_FALSE(fs::exists(dir / "small.png"));
}
