#include "rocklab/track/particle_sizing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "rocklab/track/plane.h"

namespace rocklab::track {

namespace {

[[noreturn]] void invalid(const std::string& field, const std::string& allowed, double value) {
  std::ostringstream s;
  s << "sizing." << field << " = " << value << ": " << allowed;
  throw std::invalid_argument(s.str());
}

struct Peak {
  cv::Point pixel;
  float rho;      // its distance from the background [px]
  int component;  // connected component of the foreground
};

// Step 2: the centres. Candidates are the 3x3 maxima of the distance map; highest
// first, a candidate inside the inscribed circle of a kept peak of its component
// belongs to that particle (a plateau, or the shoulder of the same disc).
std::vector<Peak> particleCentres(const cv::Mat& dist, const cv::Mat& components, double min_peak) {
  cv::Mat dilated;
  cv::dilate(dist, dilated, cv::Mat());
  std::vector<Peak> candidates;
  for (int v = 0; v < dist.rows; ++v) {
    const float* d = dist.ptr<float>(v);
    const float* m = dilated.ptr<float>(v);
    const int* c = components.ptr<int>(v);
    for (int u = 0; u < dist.cols; ++u)
      if (d[u] >= min_peak && d[u] >= m[u]) candidates.push_back({{u, v}, d[u], c[u]});
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Peak& a, const Peak& b) { return a.rho > b.rho; });
  std::vector<Peak> kept;
  for (const Peak& p : candidates) {
    bool inside = false;
    for (const Peak& k : kept)
      if (k.component == p.component && std::hypot(p.pixel.x - k.pixel.x, p.pixel.y - k.pixel.y) < k.rho) {
        inside = true;
        break;
      }
    if (!inside) kept.push_back(p);
  }
  return kept;
}

// Largest and smallest caliper width of a convex polygon (2-D points in order).
std::pair<double, double> feretDiameters(const std::vector<cv::Point2d>& hull) {
  double largest = 0.0, smallest = std::numeric_limits<double>::infinity();
  const std::size_t n = hull.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) largest = std::max(largest, cv::norm(hull[i] - hull[j]));
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Point2d a = hull[i], edge = hull[(i + 1) % n] - a;
    const double length = cv::norm(edge);
    if (!(length > 0)) continue;
    double widest = 0.0;
    for (const cv::Point2d& p : hull) widest = std::max(widest, std::abs(edge.cross(p - a)) / length);
    smallest = std::min(smallest, widest);
  }
  return {largest, std::isfinite(smallest) ? smallest : 0.0};
}

}  // namespace

void SizingSettings::validate() const {
  if (!(threshold < 256.0) || std::isnan(threshold)) invalid("threshold", "must be below 256 (< 0: Otsu's)", threshold);
  if (!(min_peak_px >= 0.5) || !std::isfinite(min_peak_px)) invalid("min_peak_px", "must be >= 0.5 px", min_peak_px);
  if (!(min_area_px >= 1.0) || !std::isfinite(min_area_px)) invalid("min_area_px", "must be >= 1 px", min_area_px);
  if (background_window_px < 0) invalid("background_window_px", "must be >= 0 px (0: automatic)", background_window_px);
  if (outline_iterations < 0 || outline_iterations > 20)
    invalid("outline_iterations", "must be 0-20", outline_iterations);
}

SizingResult sizeParticles(const cv::Mat& bgr, const geometry::Camera& camera, const geometry::Vec3& surface_point,
                           const geometry::Vec3& surface_normal, const SizingSettings& settings) {
  settings.validate();
  if (bgr.empty() || bgr.type() != CV_8UC3) throw std::invalid_argument("sizeParticles: needs a non-empty BGR image");
  if (!(surface_normal.norm() > 0.0)) throw std::invalid_argument("sizeParticles: the surface normal is zero");
  const geometry::Vec3 up = surface_normal.normalized();
  SizingResult out;

  // 1. Foreground.
  cv::Mat grey, mask;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  if (settings.flatten_background) {
    const int window = settings.background_window_px > 0 ? settings.background_window_px
                                                         : std::max(3, std::min(bgr.cols, bgr.rows) / 4);
    cv::morphologyEx(grey, grey, cv::MORPH_TOPHAT, cv::getStructuringElement(cv::MORPH_RECT, {window, window}));
  }
  if (settings.threshold >= 0) {
    out.threshold = settings.threshold;
    cv::threshold(grey, mask, settings.threshold, 255, cv::THRESH_BINARY);
  } else {
    out.threshold = cv::threshold(grey, mask, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  }
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::Mat());

  // 2. Centres and the pixels of each.
  cv::Mat components, dist;
  cv::connectedComponents(mask, components, 8, CV_32S);
  cv::distanceTransform(mask, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const std::vector<Peak> peaks = particleCentres(dist, components, settings.min_peak_px);
  std::vector<std::vector<int>> by_component;
  for (std::size_t k = 0; k < peaks.size(); ++k) {
    const auto c = static_cast<std::size_t>(peaks[k].component);
    if (by_component.size() <= c) by_component.resize(c + 1);
    by_component[c].push_back(static_cast<int>(k));
  }
  out.labels = cv::Mat::zeros(bgr.size(), CV_32S);
  std::vector<std::vector<cv::Point>> pixels(peaks.size());
  for (int v = 0; v < mask.rows; ++v) {
    const int* c = components.ptr<int>(v);
    int* label = out.labels.ptr<int>(v);
    for (int u = 0; u < mask.cols; ++u) {
      const auto component = static_cast<std::size_t>(c[u]);
      if (component == 0 || component >= by_component.size() || by_component[component].empty()) continue;
      int best = -1;
      double best_distance = std::numeric_limits<double>::infinity();
      for (int k : by_component[component]) {
        const Peak& p = peaks[static_cast<std::size_t>(k)];
        const double d = std::hypot(u - p.pixel.x, v - p.pixel.y) - p.rho;
        if (d < best_distance) best_distance = d, best = k;
      }
      label[u] = best + 1;
      pixels[static_cast<std::size_t>(best)].emplace_back(u, v);
    }
  }

  // 3. Sizes on the plane half the particle's size above the surface.
  const auto onPlane = [&](cv::Point2d pixel, double height) {
    return pixelToPlane(camera, pixel, surface_point + height * up, up);
  };
  const geometry::Vec3 across = (std::abs(up.x()) < 0.9 ? geometry::Vec3::UnitX() : geometry::Vec3::UnitY()).cross(up).normalized();
  const geometry::Vec3 along = up.cross(across);
  for (std::size_t k = 0; k < peaks.size(); ++k) {
    const std::vector<cv::Point>& mine = pixels[k];
    if (static_cast<double>(mine.size()) < settings.min_area_px) {
      for (const cv::Point& p : mine) out.labels.at<int>(p) = 0;
      continue;
    }
    SizedParticle s;
    s.label = static_cast<int>(k) + 1;
    s.centre_px = peaks[k].pixel;
    s.area_px = static_cast<double>(mine.size());
    cv::Point2d centroid(0, 0);
    std::vector<cv::Point2f> corners;
    corners.reserve(4 * mine.size());
    for (const cv::Point& p : mine) {
      centroid += cv::Point2d(p) / s.area_px;
      s.on_border = s.on_border || p.x == 0 || p.y == 0 || p.x == bgr.cols - 1 || p.y == bgr.rows - 1;
      for (const cv::Point2f corner : {cv::Point2f(-0.5f, -0.5f), cv::Point2f(0.5f, -0.5f), cv::Point2f(0.5f, 0.5f),
                                       cv::Point2f(-0.5f, 0.5f)})
        corners.push_back(cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y)) + corner);
    }
    std::vector<cv::Point2f> hull;
    cv::convexHull(corners, hull);
    bool sized = false;
    double height = 0.0;
    for (int iteration = 0; iteration <= settings.outline_iterations; ++iteration) {
      // The area: the pixel count times one pixel's footprint on the plane at the centroid.
      const auto left = onPlane(centroid + cv::Point2d(-0.5, 0), height), right = onPlane(centroid + cv::Point2d(0.5, 0), height);
      const auto top = onPlane(centroid + cv::Point2d(0, -0.5), height), bottom = onPlane(centroid + cv::Point2d(0, 0.5), height);
      if (!left || !right || !top || !bottom) break;
      s.area_m2 = s.area_px * (*right - *left).cross(*bottom - *top).norm();
      s.equivalent_diameter_m = std::sqrt(4.0 * s.area_m2 / std::numbers::pi);
      std::vector<cv::Point2d> outline;
      for (const cv::Point2f& c : hull)
        if (const auto w = onPlane(cv::Point2d(c), height)) outline.emplace_back(w->dot(across), w->dot(along));
      if (outline.size() != hull.size()) break;
      std::tie(s.feret_max_m, s.feret_min_m) = feretDiameters(outline);
      s.outline_height_m = height;
      sized = true;
      height = 0.5 * s.equivalent_diameter_m;
    }
    if (sized)
      out.particles.push_back(s);
    else  // its outline meets no plane (a ray off the surface's side): background, as SizingResult::labels says
      for (const cv::Point& p : mine) out.labels.at<int>(p) = 0;
  }
  return out;
}

}  // namespace rocklab::track
