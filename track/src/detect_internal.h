#pragma once
// The stages of detectMarkers (detect.h), one file each.
#include <cstdint>
#include <algorithm>
#include <cstring>
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

/// The first nonzero byte of row[from, width), or width; zero bytes are skipped
/// eight at a time (a marker mask is mostly zero).
inline int nextNonzero(const std::uint8_t* row, int from, int width) {
  int u = from;
  for (; u + 8 <= width; u += 8) {
    std::uint64_t word;
    std::memcpy(&word, row + u, sizeof word);
    if (word != 0) break;
  }
  while (u < width && row[u] == 0) ++u;
  return u;
}

/// 8-connected components of a mask (nonzero = set), found from its runs of set
/// pixels: the same components as cv::connectedComponentsWithStats, numbered 1, 2...
/// in raster order of their first pixel (top row first, then leftmost); a mask that
/// is mostly zero costs about a word operation per eight pixels.
struct Components {
  cv::Mat mask;                 // CV_8U, the input (shared, not copied)
  cv::Mat labels;               // CV_32S, written only where the mask is set (read through label())
  std::vector<int> areas;       // pixels per label (index 0 unused)
  std::vector<cv::Rect> boxes;  // bounding box per label (index 0 unused)
  int count() const { return static_cast<int>(areas.size()); }  // labels including 0
  /// Label of pixel (u, v) of the mask, 0 = background (the label image is not
  /// cleared: clearing it cost as much as labelling).
  int label(int u, int v) const { return mask.ptr<std::uint8_t>(v)[u] ? labels.ptr<int>(v)[u] : 0; }
  int rows() const { return mask.rows; }
  int cols() const { return mask.cols; }
};
Components labelComponents(const cv::Mat& mask);

/// A marker candidate: the pixels of its component (`core`) and the unlabelled
/// pixels 8-adjacent to them (`rim`: the antialiased edge below the thresholds).
struct Blob {
  std::vector<cv::Point> core;
  std::vector<cv::Point> rim;
};

/// Core and rim of component `label`; `box` is its bounding box. The components
/// cover the frame from pixel `origin` on (a band of rows); the points are in frame
/// coordinates.
Blob componentBlob(const Components& components, int label, const cv::Rect& box, cv::Point origin = {});

/// The leftmost and rightmost of `pixels` in each of their rows (one when they
/// coincide), by row: the same convex hull, and so the same enclosing circle.
std::vector<cv::Point> rowEnds(const std::vector<cv::Point>& pixels);

/// Redness of a BGR pixel: r − max(g, b), ≥ 0. Grey (and its white specular
/// highlight added to red) contributes nothing extra; the antialiased edge of a
/// marker counts in proportion to its coverage.
inline double redness(const cv::Vec3b& p) { return std::max(0, int(p[2]) - std::max(int(p[0]), int(p[1]))); }

/// Stage 5: redness-weighted centroid over core and rim, area and fill of the core.
Detection measureBlob(const cv::Mat& bgr, const Blob& blob);

/// Stage 5b (DetectorSettings::edge_points): sub-pixel points of the blob's outline,
/// one per core pixel and 4-neighbour rim pixel (a cut between two pieces of a split
/// blob is no edge: the other piece's pixels are no rim). Along the step from core
/// pixel p to rim pixel q the edge lies where a straight edge would give both their
/// coverages, c = redness / the redness of full paint (the brighter of p and the core
/// pixel behind it): at p + (c_p + c_q − ½)(q − p).
std::vector<cv::Point2f> blobEdges(const cv::Mat& bgr, const Blob& blob);

/// Stage 4: `pieces` touching markers of radius marker_radius_px → one blob each
/// (fewer when fewer distance-transform peaks are found; the blob itself when one).
std::vector<Blob> splitBlob(const Blob& blob, int pieces, double marker_radius_px);

/// Stage 4a: one piece per seed (px, image coordinates): k-means on the core pixels
/// started at the seeds; pieces left empty are dropped.
std::vector<Blob> splitBlobAt(const Blob& blob, std::vector<cv::Point2d> seeds);

}  // namespace rocklab::track::detail
