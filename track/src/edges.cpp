// Stage 5b of detectMarkers: the sub-pixel outline of a blob, for the model-based
// marker position (shape_fit.h).
#include <algorithm>

#include "detect_internal.h"

namespace rocklab::track::detail {

std::vector<cv::Point2f> blobEdges(const cv::Mat& bgr, const Blob& blob) {
  if (blob.core.empty()) return {};
  // A small code image over the blob's box grown by one pixel: 1 = core, 2 = rim.
  int u0 = blob.core.front().x, u1 = u0, v0 = blob.core.front().y, v1 = v0;
  for (const auto* pixels : {&blob.core, &blob.rim})
    for (const cv::Point& p : *pixels) u0 = std::min(u0, p.x), u1 = std::max(u1, p.x), v0 = std::min(v0, p.y), v1 = std::max(v1, p.y);
  const cv::Point origin(u0 - 1, v0 - 1);
  cv::Mat code = cv::Mat::zeros(v1 - v0 + 3, u1 - u0 + 3, CV_8U);
  for (const cv::Point& p : blob.core) code.at<std::uint8_t>(p - origin) = 1;
  for (const cv::Point& p : blob.rim) code.at<std::uint8_t>(p - origin) = 2;
  auto codeAt = [&](cv::Point p) { return code.at<std::uint8_t>(p - origin); };
  auto rednessAt = [&](cv::Point p) {
    if (p.x < 0 || p.y < 0 || p.x >= bgr.cols || p.y >= bgr.rows) return 0.0;
    return redness(bgr.at<cv::Vec3b>(p));
  };
  std::vector<cv::Point2f> edges;
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (const cv::Point& p : blob.core) {
    const double here = rednessAt(p);
    for (const cv::Point& step : steps) {
      const cv::Point q = p + step;
      if (codeAt(q) != 2) continue;
      const cv::Point behind = p - step;
      const double inside = codeAt(behind) == 1 ? rednessAt(behind) : here;
      const double paint = std::max(here, inside);
      double offset = 0.5;  // nothing red to go by: the edge between the pixels
      if (paint > 0) {
        const double covered_here = std::min(1.0, here / paint);
        const double covered_there = std::clamp(rednessAt(q) / paint, 0.0, 1.0);
        offset = std::clamp(covered_here + covered_there - 0.5, -0.5, 1.5);
      }
      edges.emplace_back(static_cast<float>(p.x + offset * step.x), static_cast<float>(p.y + offset * step.y));
    }
  }
  return edges;
}

}  // namespace rocklab::track::detail
