#pragma once
// The stages of detectMarkers (detect.h), one file each.
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/track/detect.h"

namespace rocklab::track::detail {

/// Stage 1: CV_8U mask (255 = red) after the HSV bands and the morphological open.
cv::Mat redMask(const cv::Mat& bgr, const DetectorSettings& settings);

/// A marker candidate: the pixels of its component (`core`) and the unlabelled
/// pixels 8-adjacent to them (`rim`: the antialiased edge below the thresholds).
struct Blob {
  std::vector<cv::Point> core;
  std::vector<cv::Point> rim;
};

/// Core and rim of component `label` of a CV_32S label image; `box` is its bounding box.
Blob componentBlob(const cv::Mat& labels, int label, const cv::Rect& box);

/// Stage 5: redness-weighted centroid over core and rim, area and fill of the core.
Detection measureBlob(const cv::Mat& bgr, const Blob& blob);

/// Stage 4: `pieces` touching markers of radius marker_radius_px → one blob each
/// (fewer when fewer distance-transform peaks are found; the blob itself when one).
std::vector<Blob> splitBlob(const Blob& blob, int pieces, double marker_radius_px);

/// Stage 4a: one piece per seed (px, image coordinates): k-means on the core pixels
/// started at the seeds; pieces left empty are dropped.
std::vector<Blob> splitBlobAt(const Blob& blob, std::vector<cv::Point2d> seeds);

}  // namespace rocklab::track::detail
