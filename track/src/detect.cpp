#include "rocklab/track/detect.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "detect_internal.h"

namespace rocklab::track {

namespace {

[[noreturn]] void invalid(const std::string& field, const std::string& what, double got) {
  std::ostringstream s;
  s << "detector." << field << ' ' << what << " (got " << got << ')';
  throw std::invalid_argument(s.str());
}

}  // namespace

void DetectorSettings::validate() const {
  if (hue_low_max < 0 || hue_low_max > 179) invalid("hue_low_max", "must be in [0, 179]", hue_low_max);
  if (hue_high_min < 0 || hue_high_min > 179) invalid("hue_high_min", "must be in [0, 179]", hue_high_min);
  if (saturation_min < 0 || saturation_min > 255) invalid("saturation_min", "must be in [0, 255]", saturation_min);
  if (value_min < 0 || value_min > 255) invalid("value_min", "must be in [0, 255]", value_min);
  if (open_kernel_px < 0 || open_kernel_px > 31) invalid("open_kernel_px", "must be in [0, 31] px", open_kernel_px);
  if (!(min_area_px >= 1.0)) invalid("min_area_px", "must be >= 1 px", min_area_px);
  if (!(max_area_px >= min_area_px)) invalid("max_area_px", "must be >= min_area_px", max_area_px);
  if (!(min_fill >= 0.0 && min_fill <= 1.0)) invalid("min_fill", "must be in [0, 1]", min_fill);
  if (!(split_ratio > 1.0) || !std::isfinite(split_ratio)) invalid("split_ratio", "must be a finite ratio > 1", split_ratio);
  if (!(split_max_fill >= 0.0 && split_max_fill <= 1.0)) invalid("split_max_fill", "must be in [0, 1]", split_max_fill);
  if (!(seeded_split_ratio >= 1.0) || !std::isfinite(seeded_split_ratio))
    invalid("seeded_split_ratio", "must be a finite ratio >= 1", seeded_split_ratio);
  if (!(expected_area_px >= 0.0) || !std::isfinite(expected_area_px))
    invalid("expected_area_px", "must be >= 0 px (0 = median of the frame)", expected_area_px);
  if (!(focal_px >= 0.0) || !std::isfinite(focal_px)) invalid("focal_px", "must be >= 0 px (0 = off)", focal_px);
  if (!std::isfinite(principal_point_px.x) || !std::isfinite(principal_point_px.y))
    invalid("principal_point_px", "must be finite", principal_point_px.x + principal_point_px.y);
  if (!(marker_max_ratio == 0.0 || marker_max_ratio >= 1.0) || !std::isfinite(marker_max_ratio))
    invalid("marker_max_ratio", "must be 0 (off) or a finite ratio >= 1", marker_max_ratio);
}

namespace {

// Component label under a predicted pixel: the pixel itself, else the nearest
// labelled pixel within `reach` px;
// 0 when none (outside the image or far from every component).
int labelNear(const detail::Components& components, cv::Point2d prediction, int reach) {
  if (!std::isfinite(prediction.x) || !std::isfinite(prediction.y)) return 0;
  const long u = std::lround(prediction.x), v = std::lround(prediction.y);
  int best = 0;
  long bestD = std::numeric_limits<long>::max();
  for (long dv = -reach; dv <= reach; ++dv)
    for (long du = -reach; du <= reach; ++du) {
      const long uu = u + du, vv = v + dv, d = du * du + dv * dv;
      if (uu < 0 || vv < 0 || uu >= components.cols() || vv >= components.rows() || d >= bestD ||
          d > long(reach) * reach)
        continue;
      const int label = components.label(static_cast<int>(uu), static_cast<int>(vv));
      if (label != 0) best = label, bestD = d;
    }
  return best;
}

}  // namespace

std::vector<Detection> detectMarkers(const cv::Mat& bgr, const DetectorSettings& settings) {
  return detectMarkers(bgr, settings, {});
}

std::vector<Detection> detectMarkers(const cv::Mat& bgr, const DetectorSettings& settings,
                                     const std::vector<cv::Point2d>& predictions,
                                     const std::vector<double>& prediction_areas) {
  settings.validate();
  if (!prediction_areas.empty() && prediction_areas.size() != predictions.size())
    throw std::invalid_argument("detectMarkers: " + std::to_string(prediction_areas.size()) +
                                " prediction areas for " + std::to_string(predictions.size()) +
                                " predictions (allowed: none, or one a prediction)");
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("detectMarkers: the image must be 8-bit BGR (CV_8UC3) and not empty");

  // 1. segment.
  cv::Range rows;
  const cv::Mat mask = detail::redMask(bgr, settings, rows);
  if (rows.empty()) return {};

  // 2. components (label 0 is the background), labelled on the rows with red pixels
  // and one more on either side (the rim of stage 5); `components` row 0 is frame row
  // origin.y.
  const cv::Range band(std::max(0, rows.start - 1), std::min(mask.rows, rows.end + 1));
  const cv::Point origin(0, band.start);
  const detail::Components components = detail::labelComponents(mask.rowRange(band));
  const int count = components.count();
  std::vector<int> candidates;
  std::vector<double> areas;
  for (int label = 1; label < count; ++label) {
    const double area = components.areas[static_cast<std::size_t>(label)];
    if (area < settings.min_area_px) continue;
    candidates.push_back(label);
    areas.push_back(area);
  }
  if (candidates.empty()) return {};

  // 3. reference area of one marker.
  double reference = settings.expected_area_px;
  if (reference == 0.0) {
    std::vector<double> sorted = areas;
    const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), middle, sorted.end());
    reference = *middle;
  }

  // Predictions per component (stage 4a): which tracks expect to be in it.
  std::vector<std::vector<cv::Point2d>> predicted(static_cast<std::size_t>(count));
  std::vector<double> predicted_area(static_cast<std::size_t>(count), 0.0);  // of a lone prediction
  // Within a pixel (rounding): a prediction outside the blob belongs to a marker
  // that is hidden or elsewhere, and must not cut a lone marker in two.
  const int reach = 1;
  for (std::size_t k = 0; k < predictions.size(); ++k)
    if (const int label = labelNear(components, predictions[k] - cv::Point2d(origin), reach); label > 0) {
      const auto l = static_cast<std::size_t>(label);
      predicted[l].push_back(predictions[k]);
      predicted_area[l] = prediction_areas.empty() ? 0.0 : prediction_areas[k];
    }

  // The reference at a component (its box centre): off the optical axis a marker
  // covers 1 / cos θ times its area on the axis (with focal_px and a fixed area).
  auto referenceAt = [&](const cv::Rect& box) {
    if (settings.focal_px <= 0.0 || settings.expected_area_px == 0.0) return reference;
    const cv::Point2d centre = cv::Point2d(origin) + cv::Point2d(box.x + 0.5 * (box.width - 1), box.y + 0.5 * (box.height - 1));
    const cv::Point2d off = (centre - settings.principal_point_px) / settings.focal_px;
    return reference * std::sqrt(1.0 + off.dot(off));
  };

  std::vector<Detection> out;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const int label = candidates[c];
    const cv::Rect& box = components.boxes[static_cast<std::size_t>(label)];
    const detail::Blob blob = detail::componentBlob(components, label, box, origin);
    const std::vector<cv::Point2d>& seeds = predicted[static_cast<std::size_t>(label)];
    // One tracked marker of known size in it: one marker covers up to that size.
    const double local = seeds.size() == 1 ? std::max(referenceAt(box), predicted_area[static_cast<std::size_t>(label)])
                                           : referenceAt(box);
    // More than one marker can cover (markers of one size): stage 4c.
    const double marker_max = settings.marker_max_ratio > 0 ? settings.marker_max_ratio * local
                                                            : std::numeric_limits<double>::infinity();
    // 5. measure the whole component; 4. split it if it is touching markers
    // (large and not round, or more than one marker covers), measuring each piece; 6. filter.
    std::vector<Detection> found{detail::measureBlob(bgr, blob)};
    std::vector<detail::Blob> pieces;
    if (seeds.size() >= 2 && areas[c] > settings.seeded_split_ratio * local) {
      pieces = detail::splitBlobAt(blob, seeds);
    } else if ((areas[c] > settings.split_ratio * local && found[0].fill < settings.split_max_fill) ||
               areas[c] > marker_max) {
      const int k = std::max(2, static_cast<int>(std::lround(areas[c] / local)));
      pieces = detail::splitBlob(blob, k, std::sqrt(local / std::numbers::pi));
    }
    if (pieces.size() > 1) {
      found.clear();
      for (const detail::Blob& piece : pieces) {
        found.push_back(detail::measureBlob(bgr, piece));
        if (settings.edge_points) found.back().edge_points = detail::blobEdges(bgr, piece);
      }
    } else if (settings.edge_points) {
      found[0].edge_points = detail::blobEdges(bgr, blob);
    }
    for (Detection& d : found) {
      if (d.area_px < settings.min_area_px || d.area_px > settings.max_area_px) continue;
      if (d.fill < settings.min_fill) continue;
      d.merged = d.area_px > marker_max;
      out.push_back(d);
    }
  }
  return out;
}

}  // namespace rocklab::track
