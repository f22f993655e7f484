#pragma once
// The stages of detectMarkers (detect.h), one file each.
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/track/detect.h"

namespace rocklab::track::detail {

/// Stage 1a: CV_8U mask (255 = red): the pixels whose OpenCV 8-bit HSV
/// (cv::cvtColor COLOR_BGR2HSV) lies in one of the two hue bands with the saturation
/// and value minima, bit for bit as cvtColor + inRange, in one pass over the BGR
/// pixels. `rows`: the rows with red pixels (empty when none).
cv::Mat redPixels(const cv::Mat& bgr, const DetectorSettings& settings, cv::Range& rows);

/// Stage 1: redPixels after the morphological open (the same mask as opening the
/// whole image); `rows` as redPixels gives them (the open only removes pixels).
cv::Mat redMask(const cv::Mat& bgr, const DetectorSettings& settings, cv::Range& rows);

/// 8-connected components of a mask (nonzero = set), found from its runs of set
/// pixels: the same components as cv::connectedComponentsWithStats, numbered 1, 2...
/// in raster order of their first pixel (top row first, then leftmost); a mask that
/// is mostly zero costs about a word operation per eight pixels.
struct Components {
  cv::Mat labels;               // CV_32S, 0 = background
  std::vector<int> areas;       // pixels per label (index 0 unused)
  std::vector<cv::Rect> boxes;  // bounding box per label (index 0 unused)
  int count() const { return static_cast<int>(areas.size()); }  // labels including 0
};
Components labelComponents(const cv::Mat& mask);

/// A marker candidate: the pixels of its component (`core`) and the unlabelled
/// pixels 8-adjacent to them (`rim`: the antialiased edge below the thresholds).
struct Blob {
  std::vector<cv::Point> core;
  std::vector<cv::Point> rim;
};

/// Core and rim of component `label` of a CV_32S label image; `box` is its bounding
/// box. The label image covers the frame from pixel `origin` on (a band of rows);
/// the points are in frame coordinates.
Blob componentBlob(const cv::Mat& labels, int label, const cv::Rect& box, cv::Point origin = {});

/// Stage 5: redness-weighted centroid over core and rim, area and fill of the core.
Detection measureBlob(const cv::Mat& bgr, const Blob& blob);

/// Stage 4: `pieces` touching markers of radius marker_radius_px → one blob each
/// (fewer when fewer distance-transform peaks are found; the blob itself when one).
std::vector<Blob> splitBlob(const Blob& blob, int pieces, double marker_radius_px);

/// Stage 4a: one piece per seed (px, image coordinates): k-means on the core pixels
/// started at the seeds; pieces left empty are dropped.
std::vector<Blob> splitBlobAt(const Blob& blob, std::vector<cv::Point2d> seeds);

}  // namespace rocklab::track::detail
