// The built-in plotter, drawn with OpenCV: the fallback when gnuplot is missing
// (plot_internal.h). PNG only; a log axis is drawn as log10 of the values.
#include "analysis/plot_internal.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "rocklab/render/image_io.h"

namespace rocklab::experiments::detail {

namespace {


// Okabe–Ito colour-blind-safe palette in OpenCV's BGR order; its yellow is left
// out (unreadable on white).
const std::array<cv::Scalar, 7> kPalette = {
    cv::Scalar(178, 114, 0),    // blue
    cv::Scalar(0, 94, 213),     // vermillion
    cv::Scalar(115, 158, 0),    // bluish green
    cv::Scalar(0, 159, 230),    // orange
    cv::Scalar(167, 121, 204),  // reddish purple
    cv::Scalar(233, 180, 86),   // sky blue
    cv::Scalar(0, 0, 0)};       // black
const cv::Scalar kWhite(255, 255, 255), kInk(30, 30, 30), kGrid(228, 228, 228), kFrame(150, 150, 150);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kShift = 4;  // sub-pixel bits for cv::line / cv::circle

// Ticks at multiples of a "nice" step (1, 2 or 5 × 10^k), about `target` of them.
std::vector<double> niceTicks(AxisRange r, double target, double& step) {
  const double raw = (r.hi - r.lo) / std::max(target, 2.0);
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / decade;
  step = (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0) * decade;
  std::vector<double> ticks;
  if (!std::isfinite(step) || step <= 0) return ticks;
  // (At most 100 ticks: when |lo| / step exceeds 2^53, k += 1 would not advance.)
  for (double k = std::ceil(r.lo / step - 1e-9); k * step <= r.hi + 1e-9 * step && ticks.size() < 100; k += 1.0)
    ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);  // no "-0"
  return ticks;
}

std::string tickLabel(double v, double step) {
  char buf[32];
  if (std::max(std::abs(v), step) >= 1e5 || step < 1e-4)
    std::snprintf(buf, sizeof buf, "%.3g", v);
  else
    std::snprintf(buf, sizeof buf, "%.*f", std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9))), v);
  return buf;
}

// Liang–Barsky: cuts the segment a–b to the rectangle r; false when none of it is inside.
bool clipSegment(cv::Point2d& a, cv::Point2d& b, const cv::Rect2d& r) {
  const cv::Point2d d = b - a;
  const double p[4] = {-d.x, d.x, -d.y, d.y}, q[4] = {a.x - r.x, r.x + r.width - a.x, a.y - r.y, r.y + r.height - a.y};
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0) {
      if (q[k] < 0) return false;  // parallel to this edge and outside it
    } else if (p[k] < 0) {
      t0 = std::max(t0, q[k] / p[k]);
    } else {
      t1 = std::min(t1, q[k] / p[k]);
    }
  }
  if (t0 > t1) return false;
  b = a + t1 * d;
  a = a + t0 * d;
  return true;
}

// Pixels → OpenCV's fixed point with kShift fractional bits.
cv::Point fixedPoint(cv::Point2d p) {
  return {static_cast<int>(std::lround(p.x * (1 << kShift))), static_cast<int>(std::lround(p.y * (1 << kShift)))};
}

void text(cv::Mat& img, const std::string& s, cv::Point at, double scale, int thickness = 1) {
  cv::putText(img, s, at, kFont, scale, kInk, thickness, cv::LINE_AA);
}
cv::Size textSize(const std::string& s, double scale, int thickness = 1) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, thickness, &baseline);
}

// Text rotated 90° counter-clockwise, centred on `centre` (drawn apart, then
// composited with a per-pixel minimum, which keeps dark ink on the white page).
void verticalText(cv::Mat& img, const std::string& s, cv::Point centre, double scale) {
  const cv::Size sz = textSize(s, scale);
  cv::Mat strip(sz.height + 8, sz.width + 4, CV_8UC3, kWhite), turned;
  text(strip, s, {2, sz.height + 2}, scale);
  cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  cv::Rect dst(centre.x - turned.cols / 2, centre.y - turned.rows / 2, turned.cols, turned.rows);
  dst &= cv::Rect(0, 0, img.cols, img.rows);
  cv::Mat roi = img(dst);
  cv::min(roi, turned(cv::Rect(dst.x - (centre.x - turned.cols / 2), dst.y - (centre.y - turned.rows / 2),
                               dst.width, dst.height)),
          roi);
}

/// The spec with each log axis turned into a linear axis of log10 of the values
/// (non-positive values left out), its label saying so.
PlotSpec withLogAxesAsLog10(PlotSpec spec) {
  auto toLog = [](double v) { return v > 0 ? std::log10(v) : NAN; };
  for (const bool x_axis : {true, false}) {
    if (!(x_axis ? spec.log_x : spec.log_y)) continue;
    for (PlotSeries& s : spec.series)
      for (double& v : x_axis ? s.x : s.y) v = toLog(v);
    auto& range = x_axis ? spec.x_range : spec.y_range;
    if (range) range = std::pair{toLog(range->first), toLog(range->second)};
    (x_axis ? spec.x_label : spec.y_label) = "log10 of " + (x_axis ? spec.x_label : spec.y_label);
  }
  spec.log_x = spec.log_y = false;
  return spec;
}

/// One panel as an image of its own size.
cv::Mat drawPanel(const PlotSpec& logged) {
  const PlotSpec spec = withLogAxesAsLog10(logged);

  // Layout: margins for the title (top), tick labels and axis labels (left, bottom).
  cv::Mat img(spec.height, spec.width, CV_8UC3, kWhite);
  const cv::Rect box(84, spec.title.empty() ? 20 : 46, spec.width - 84 - 24,
                     spec.height - (spec.title.empty() ? 20 : 46) - 62);
  const AxisRange xr = axisRange(spec, true), yr = axisRange(spec, false);
  // Data → pixels inside the plot box (clamped to ±1e12 so that far-off points stay finite).
  auto px = [&](double x, double y) {
    return cv::Point2d(std::clamp((x - xr.lo) / (xr.hi - xr.lo) * (box.width - 1), -1e12, 1e12),
                       std::clamp((yr.hi - y) / (yr.hi - yr.lo) * (box.height - 1), -1e12, 1e12));
  };

  // Grid, ticks and tick labels.
  double xstep = 0, ystep = 0;
  for (double t : niceTicks(xr, box.width / 110.0, xstep)) {
    const int x = box.x + static_cast<int>(std::lround(px(t, yr.lo).x));
    cv::line(img, {x, box.y}, {x, box.y + box.height - 1}, kGrid, 1);
    cv::line(img, {x, box.y + box.height}, {x, box.y + box.height + 5}, kInk, 1);
    const std::string label = tickLabel(t, xstep);
    text(img, label, {x - textSize(label, 0.45).width / 2, box.y + box.height + 22}, 0.45);
  }
  for (double t : niceTicks(yr, box.height / 70.0, ystep)) {
    const int y = box.y + static_cast<int>(std::lround(px(xr.lo, t).y));
    cv::line(img, {box.x, y}, {box.x + box.width - 1, y}, kGrid, 1);
    cv::line(img, {box.x - 5, y}, {box.x, y}, kInk, 1);
    const std::string label = tickLabel(t, ystep);
    text(img, label, {box.x - 9 - textSize(label, 0.45).width, y + 5}, 0.45);
  }

  // Series, clipped to the plot box (OpenCV's fixed-point drawing overflows far outside the image).
  cv::Mat plot = img(box);
  const cv::Rect2d inside(-8, -8, box.width + 16, box.height + 16);  // the box and a margin for line caps
  for (std::size_t k = 0; k < spec.series.size(); ++k) {
    const PlotSeries& s = spec.series[k];
    const cv::Scalar colour = kPalette[colourIndexOf(s, k) % kPalette.size()];
    auto finite = [&](std::size_t i) { return std::isfinite(s.x[i]) && std::isfinite(s.y[i]); };
    if (s.style != PlotSeries::Style::Points)
      for (std::size_t i = 1; i < s.x.size(); ++i)
        if (cv::Point2d a = px(s.x[i - 1], s.y[i - 1]), b = px(s.x[i], s.y[i]);
            finite(i - 1) && finite(i) && clipSegment(a, b, inside))
          cv::line(plot, fixedPoint(a), fixedPoint(b), colour, 2, cv::LINE_AA, kShift);
    if (s.style != PlotSeries::Style::Line)
      for (std::size_t i = 0; i < s.x.size(); ++i)
        if (finite(i) && inside.contains(px(s.x[i], s.y[i])))
          cv::circle(plot, fixedPoint(px(s.x[i], s.y[i])), 4 << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
  }
  cv::rectangle(img, box, kInk, 1);

  // Title, axis labels (the y label turned to read bottom-up).
  text(img, spec.title, {(spec.width - textSize(spec.title, 0.7, 2).width) / 2, 30}, 0.7, 2);
  text(img, spec.x_label, {box.x + (box.width - textSize(spec.x_label, 0.55).width) / 2, spec.height - 12}, 0.55);
  if (!spec.y_label.empty()) verticalText(img, spec.y_label, {16, box.y + box.height / 2}, 0.55);

  // Legend box in the corner of the plot box that hides the fewest drawn pixels (top right on a tie).
  std::vector<std::size_t> entries;
  int text_w = 0;
  for (std::size_t k = 0; k < spec.series.size(); ++k)
    if (!spec.series[k].label.empty()) {
      entries.push_back(k);
      text_w = std::max(text_w, textSize(spec.series[k].label, 0.5).width);
    }
  if (!entries.empty()) {
    const int row = 22, w = text_w + 56, h = static_cast<int>(entries.size()) * row + 10;
    cv::Rect legend;
    int least = INT_MAX;
    for (int corner = 0; corner < 4; ++corner) {
      const cv::Rect r(corner % 2 == 0 ? box.x + box.width - w - 10 : box.x + 10,
                       corner < 2 ? box.y + 10 : box.y + box.height - h - 10, w, h);
      cv::Mat grey;
      cv::cvtColor(img(r & box), grey, cv::COLOR_BGR2GRAY);
      const int inked = cv::countNonZero(grey < 200);  // series and frame, not the grid (228)
      if (inked < least) least = inked, legend = r;
    }
    cv::rectangle(img, legend, kWhite, cv::FILLED);
    cv::rectangle(img, legend, kFrame, 1);
    for (std::size_t e = 0; e < entries.size(); ++e) {
      const PlotSeries& s = spec.series[entries[e]];
      const cv::Scalar colour = kPalette[colourIndexOf(s, entries[e]) % kPalette.size()];
      const int y = legend.y + 5 + row / 2 + static_cast<int>(e) * row;
      if (s.style != PlotSeries::Style::Points)
        cv::line(img, {legend.x + 8, y}, {legend.x + 38, y}, colour, 2, cv::LINE_AA);
      if (s.style != PlotSeries::Style::Line) cv::circle(img, {legend.x + 23, y}, 4, colour, cv::FILLED, cv::LINE_AA);
      text(img, s.label, {legend.x + 46, y + 5}, 0.5);
    }
  }

  return img;
}

}  // namespace

void drawPlotWithOpenCv(const std::vector<PlotSpec>& panels, const std::filesystem::path& png) {
  int height = 0;
  for (const PlotSpec& spec : panels) height = std::max(height, spec.height);
  std::vector<cv::Mat> row;
  for (const PlotSpec& spec : panels) {
    cv::Mat panel = drawPanel(spec);
    if (panel.rows < height) cv::copyMakeBorder(panel, panel, 0, height - panel.rows, 0, 0, cv::BORDER_CONSTANT, kWhite);
    row.push_back(panel);
  }
  cv::Mat img;
  cv::hconcat(row, img);
  render::writePng(png, img);  // atomic: "<png>.partial", then rename
}

}  // namespace rocklab::experiments::detail
