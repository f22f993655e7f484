#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "detect_internal.h"

namespace rocklab::track::detail {

std::vector<cv::Point> rowEnds(const std::vector<cv::Point>& pixels) {
  if (pixels.empty()) return {};
  int v0 = pixels.front().y, v1 = v0;
  for (const cv::Point& p : pixels) v0 = std::min(v0, p.y), v1 = std::max(v1, p.y);
  std::vector<int> left(static_cast<std::size_t>(v1 - v0 + 1), std::numeric_limits<int>::max());
  std::vector<int> right(left.size(), std::numeric_limits<int>::min());
  for (const cv::Point& p : pixels) {
    const auto row = static_cast<std::size_t>(p.y - v0);
    left[row] = std::min(left[row], p.x);
    right[row] = std::max(right[row], p.x);
  }
  std::vector<cv::Point> ends;
  ends.reserve(2 * left.size());
  for (std::size_t row = 0; row < left.size(); ++row) {
    if (left[row] > right[row]) continue;  // no pixel in this row (a piece of a split blob)
    const int v = v0 + static_cast<int>(row);
    ends.emplace_back(left[row], v);
    if (right[row] != left[row]) ends.emplace_back(right[row], v);
  }
  return ends;
}

Blob componentBlob(const Components& components, int label, const cv::Rect& box, cv::Point origin) {
  Blob blob;
  blob.core.reserve(static_cast<std::size_t>(box.area()));
  // The box grown by one pixel (clipped to the image) holds the core and its rim.
  const int u0 = std::max(0, box.x - 1), u1 = std::min(components.cols() - 1, box.x + box.width);
  const int v0 = std::max(0, box.y - 1), v1 = std::min(components.rows() - 1, box.y + box.height);
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      const int here = components.label(u, v);
      if (here == label) {
        blob.core.emplace_back(origin.x + u, origin.y + v);
        continue;
      }
      if (here != 0) continue;  // another component's pixel is never our rim
      bool touches = false;
      for (int dv = -1; dv <= 1 && !touches; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= components.rows()) continue;
        for (int du = -1; du <= 1; ++du) {
          const int uu = u + du;
          if (uu >= 0 && uu < components.cols() && components.label(uu, vv) == label) {
            touches = true;
            break;
          }
        }
      }
      if (touches) blob.rim.emplace_back(origin.x + u, origin.y + v);
    }
  }
  return blob;
}

Detection measureBlob(const cv::Mat& bgr, const Blob& blob) {
  Detection d;
  // Redness-weighted centroid over core and rim; the plain mean if nothing is red.
  double su = 0, sv = 0, sw = 0;
  for (const auto* pixels : {&blob.core, &blob.rim})
    for (const cv::Point& p : *pixels) {
      const double w = redness(bgr.at<cv::Vec3b>(p));
      su += w * p.x, sv += w * p.y, sw += w;
    }
  if (sw > 0) {
    d.centroid = cv::Point2d(su / sw, sv / sw);
  } else {
    for (const cv::Point& p : blob.core) su += p.x, sv += p.y;
    d.centroid = cv::Point2d(su / blob.core.size(), sv / blob.core.size());
  }
  d.area_px = static_cast<double>(blob.core.size());
  d.radius_px = std::sqrt(d.area_px / std::numbers::pi);
  // Fill: the enclosing circle of the pixel centres grown by half a pixel covers
  // the pixel squares (up to the corners); capped at 1 for tiny blobs. The circle
  // of the rows' end pixels (the others lie between them).
  cv::Point2f centre;
  float radius = 0;
  cv::minEnclosingCircle(rowEnds(blob.core), centre, radius);
  const double enclosing = std::numbers::pi * (radius + 0.5) * (radius + 0.5);
  d.fill = std::min(1.0, d.area_px / enclosing);
  return d;
}

}  // namespace rocklab::track::detail
