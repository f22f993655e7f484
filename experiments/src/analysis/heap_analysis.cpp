#include "analysis/heap_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rocklab::experiments {

namespace {

constexpr double kBandLo = 0.2, kBandHi = 0.8;  // flank band, fractions of the view's peak height
constexpr double kEmpty = -std::numeric_limits<double>::infinity();

// Silhouette of one side view: h[i] is the height above the base of bin first + i, whose centre is at
// u = (first + i + 0.5) * width from the heap axis; kEmpty where no ball reaches the bin.
struct Silhouette {
  long long first = 0;
  double width = 0;
  std::vector<double> h;
  double centre(std::size_t i) const { return (static_cast<double>(first + static_cast<long long>(i)) + 0.5) * width; }
};

Silhouette silhouette(const std::vector<geometry::Sphere>& balls, int axis, double axis_u, double base_z, double w) {
  Silhouette s;
  s.width = w;
  long long lo = std::numeric_limits<long long>::max(), hi = std::numeric_limits<long long>::min();
  for (const geometry::Sphere& b : balls) {
    const double u = b.centre[axis] - axis_u;
    lo = std::min(lo, static_cast<long long>(std::floor((u - b.radius) / w)));
    hi = std::max(hi, static_cast<long long>(std::floor((u + b.radius) / w)));
  }
  s.first = lo;
  s.h.assign(static_cast<std::size_t>(hi - lo + 1), kEmpty);
  // Each ball raises the bins it overlaps to its outline height at the bin centre.
  for (const geometry::Sphere& b : balls) {
    const double u = b.centre[axis] - axis_u, r = b.radius, z = b.centre.z() - base_z;
    const auto k0 = static_cast<long long>(std::floor((u - r) / w)), k1 = static_cast<long long>(std::floor((u + r) / w));
    for (long long k = k0; k <= k1; ++k) {
      const auto i = static_cast<std::size_t>(k - lo);
      const double d = s.centre(i) - u;
      s.h[i] = std::max(s.h[i], z + std::sqrt(std::max(0.0, r * r - d * d)));
    }
  }
  return s;
}

struct FlankFit {
  double angle_deg;
  double toe_u;  // u where the fitted line reaches the base (h = 0)
};

// Least-squares line h = a + b u through the band bins of one flank, bins [begin, end) of the silhouette.
// Refuses a flank that is no slope: too few band bins, a band narrower than a ball (the rounded edge of a flat
// layer), or a line that would not rise through the band (0.6 × peak) within the flank's own width (band bins
// scattered along a flat top, where gaps between balls dip into the band).
FlankFit fitFlank(const Silhouette& s, std::size_t begin, std::size_t end, double peak_u, double peak,
                  double diameter, const char* name) {
  std::vector<std::pair<double, double>> band;  // (u, h) of the band bins
  double width = 0, mu = 0, mh = 0;             // flank width from the peak (m); mean u and h of the band
  for (std::size_t i = begin; i < end; ++i) {
    if (s.h[i] == kEmpty) continue;
    width = std::max(width, std::abs(s.centre(i) - peak_u));
    if (s.h[i] < kBandLo * peak || s.h[i] > kBandHi * peak) continue;
    band.emplace_back(s.centre(i), s.h[i]);
    mu += s.centre(i), mh += s.h[i];
  }
  const double n = static_cast<double>(band.size());
  std::ostringstream why;
  if (band.size() < 3 || band.back().first - band.front().first < diameter) {
    why << band.size() << " bins between 20 % and 80 % of the peak height " << peak << " m";
    if (!band.empty()) why << ", spanning " << band.back().first - band.front().first << " m";
    why << " (need at least 3 bins spanning one mean ball diameter, " << diameter
        << " m): not a heap, or bin_width too coarse";
  } else {
    // Slope from sums centred on the band's mean.
    mu /= n, mh /= n;
    double suu = 0, suh = 0;
    for (const auto& [u, h] : band) suu += (u - mu) * (u - mu), suh += (u - mu) * (h - mh);
    const double b = suh / suu;
    const double rise = std::abs(b) * width;
    if (rise >= (kBandHi - kBandLo) * peak) return {std::atan(std::abs(b)) * 180.0 / std::numbers::pi, mu - mh / b};
    why << "a fitted slope of " << std::atan(std::abs(b)) * 180.0 / std::numbers::pi << " deg that rises only "
        << rise << " m over the flank's " << width << " m (the 20-80 % band is " << (kBandHi - kBandLo) * peak
        << " m): not a heap";
  }
  throw std::invalid_argument(std::string("angleOfRepose: the ") + name + " flank has " + why.str());
}

}  // namespace

HeapAngle angleOfRepose(const std::vector<geometry::Sphere>& balls, double base_z, double bin_width) {
  if (balls.empty()) throw std::invalid_argument("angleOfRepose: no balls");
  if (!(bin_width > 0)) throw std::invalid_argument("angleOfRepose: bin_width must be > 0");

  // Heap axis, peak height and mean ball diameter.
  HeapAngle out;
  out.balls = balls.size();
  double cx = 0, cy = 0, diameter = 0, top = -INFINITY;
  double lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY, hi_y = -INFINITY;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const geometry::Sphere& b = balls[i];
    if (!b.centre.allFinite() || !std::isfinite(b.radius))
      throw std::invalid_argument("angleOfRepose: ball " + std::to_string(i) + " has a non-finite centre or radius");
    cx += b.centre.x(), cy += b.centre.y(), diameter += 2 * b.radius;
    top = std::max(top, b.centre.z() + b.radius);
    lo_x = std::min(lo_x, b.centre.x()), hi_x = std::max(hi_x, b.centre.x());
    lo_y = std::min(lo_y, b.centre.y()), hi_y = std::max(hi_y, b.centre.y());
  }
  const double n = static_cast<double>(balls.size());
  cx /= n, cy /= n, diameter /= n;
  // The silhouettes hold one bin per bin_width of the balls' extent: refuse absurd sizes (a ball flung far away).
  if (std::max(hi_x - lo_x, hi_y - lo_y) + 2 * diameter > 1e7 * bin_width)
    throw std::invalid_argument("angleOfRepose: the balls span " + std::to_string(std::max(hi_x - lo_x, hi_y - lo_y)) +
                                " m, over 10^7 bins of bin_width; remove balls far from the heap");
  out.height_m = top - base_z;

  // Two side views, two flanks each, split at the view's peak bin.
  static const char* const kNames[4] = {"-x", "+x", "-y", "+y"};
  for (int axis = 0; axis < 2; ++axis) {
    const Silhouette s = silhouette(balls, axis, axis == 0 ? cx : cy, base_z, bin_width);
    const auto peak_it = std::max_element(s.h.begin(), s.h.end());
    const auto p = static_cast<std::size_t>(peak_it - s.h.begin());
    for (int side = 0; side < 2; ++side) {
      const FlankFit f = side == 0 ? fitFlank(s, 0, p, s.centre(p), *peak_it, diameter, kNames[2 * axis])
                                   : fitFlank(s, p + 1, s.h.size(), s.centre(p), *peak_it, diameter, kNames[2 * axis + 1]);
      out.flank_deg.push_back(f.angle_deg);
      out.base_radius_m += std::abs(f.toe_u) / 4;
    }
  }

  // Mean and sample standard deviation of the four flanks.
  for (double a : out.flank_deg) out.mean_deg += a / 4;
  double ss = 0;
  for (double a : out.flank_deg) ss += (a - out.mean_deg) * (a - out.mean_deg);
  out.std_deg = std::sqrt(ss / 3);

  std::ostringstream method;
  method << "side-view silhouettes (x-z and y-z about the mean (x, y) of the balls; per " << bin_width * 1e3
         << " mm bin the highest ball outline), each of the four flanks fitted by least squares between 20 % and "
            "80 % of the peak height, angle = atan(|slope|), mean and sample std of the four flanks";
  out.method = method.str();
  return out;
}

}  // namespace rocklab::experiments
