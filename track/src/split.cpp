#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "detect_internal.h"

namespace rocklab::track::detail {

namespace {

// Index of the centre nearest to p.
std::size_t nearest(const std::vector<cv::Point2d>& centres, const cv::Point& p) {
  std::size_t best = 0;
  double bestD = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < centres.size(); ++c) {
    const double du = p.x - centres[c].x, dv = p.y - centres[c].y, d = du * du + dv * dv;
    if (d < bestD) bestD = d, best = c;
  }
  return best;
}

}  // namespace

std::vector<Blob> splitBlob(const Blob& blob, int pieces, double marker_radius_px) {
  if (pieces < 2 || blob.core.empty()) return {blob};
  // Seeds: the highest distance-transform peaks (centres of the inscribed discs),
  // each one suppressing a disc of one marker radius so the next seed is another marker.
  const cv::Rect box = cv::boundingRect(blob.core);
  cv::Mat mask = cv::Mat::zeros(box.height + 2, box.width + 2, CV_8U);  // one-pixel frame: the border is outside
  for (const cv::Point& p : blob.core) mask.at<unsigned char>(p.y - box.y + 1, p.x - box.x + 1) = 255;
  cv::Mat distance;
  cv::distanceTransform(mask, distance, cv::DIST_L2, cv::DIST_MASK_5);
  const int suppress = std::max(1, static_cast<int>(std::lround(marker_radius_px)));
  std::vector<cv::Point2d> centres;
  for (int k = 0; k < pieces; ++k) {
    double peak = 0;
    cv::Point at;
    cv::minMaxLoc(distance, nullptr, &peak, nullptr, &at);
    if (!(peak > 0)) break;
    centres.emplace_back(at.x + box.x - 1, at.y + box.y - 1);
    cv::circle(distance, at, suppress, cv::Scalar(0), cv::FILLED);
  }
  if (centres.size() < 2) return {blob};
  return splitBlobAt(blob, std::move(centres));
}

std::vector<Blob> splitBlobAt(const Blob& blob, std::vector<cv::Point2d> centres) {
  if (centres.size() < 2 || blob.core.empty()) return {blob};
  // k-means (Lloyd) on the core pixel coordinates from those seeds.
  std::vector<std::size_t> owner(blob.core.size(), centres.size());
  for (int iteration = 0; iteration < 50; ++iteration) {
    bool changed = false;
    for (std::size_t i = 0; i < blob.core.size(); ++i) {
      const std::size_t c = nearest(centres, blob.core[i]);
      if (c != owner[i]) owner[i] = c, changed = true;
    }
    if (!changed) break;
    std::vector<cv::Point2d> sum(centres.size(), cv::Point2d(0, 0));
    std::vector<double> count(centres.size(), 0.0);
    for (std::size_t i = 0; i < blob.core.size(); ++i) {
      sum[owner[i]] += cv::Point2d(blob.core[i]);
      count[owner[i]] += 1.0;
    }
    for (std::size_t c = 0; c < centres.size(); ++c)
      if (count[c] > 0) centres[c] = sum[c] / count[c];
  }

  // Pieces: every core and rim pixel goes to its nearest centre.
  std::vector<Blob> out(centres.size());
  for (std::size_t i = 0; i < blob.core.size(); ++i) out[owner[i]].core.push_back(blob.core[i]);
  for (const cv::Point& p : blob.rim) out[nearest(centres, p)].rim.push_back(p);
  std::erase_if(out, [](const Blob& b) { return b.core.empty(); });
  return out;
}

}  // namespace rocklab::track::detail
