#pragma once
// Red marker detection in one colour frame (BGR, 8 bits per channel).
//
// The pipeline, in order (src/detect.cpp):
//   1. segment    — HSV thresholds, two hue bands around red (OpenCV's 8-bit hue
//                   runs 0..179, red wraps at 0/180): the pixels cv::cvtColor +
//                   cv::inRange would give, bit for bit, tested in one pass over the
//                   BGR pixels (a vectorised superset test, then OpenCV's fixed-point
//                   HSV on the few candidates); then a morphological open (a square
//                   of open_kernel_px) that removes specks and threads, on the rows
//                   with red pixels only;
//   2. components — 8-connected components with their pixel counts, from the runs
//                   of mask pixels (a mostly empty mask costs little);
//   3. reference  — the area of one marker: expected_area_px, or (0) the median
//                   area of this frame's components; with focal_px, expected_area_px
//                   is the area on the optical axis and grows off it as 1 / cos θ
//                   (a ball's image at the same depth), θ the angle of the
//                   component's box centre from the axis;
//   4. split      — (a) prediction-seeded: a component into which two or more of the
//                   given predictions fall (the pixel under the prediction or one of
//                   its 8 neighbours) and larger
//                   than seeded_split_ratio × reference is cut into one piece per
//                   prediction: k-means (Lloyd) on its pixel coordinates started at the
//                   predictions, so each track keeps the piece nearest where it was
//                   going (touching markers that move together stay apart);
//                   (b) otherwise, by size: a component larger than split_ratio ×
//                   reference and less round than split_max_fill (one disc fills ~0.9 of its enclosing circle,
//                   two touching discs 0.5, three or four in a clump 0.65–0.7) is
//                   touching markers: k = round(area / reference) pieces, seeded at the k
//                   highest distance-transform peaks (each peak suppresses a disc
//                   of one marker radius), refined by k-means (Lloyd) on the
//                   pixel coordinates; a pixel belongs to the nearest piece centre,
//                   so two equal touching discs are cut along their bisector;
//                   (c) with marker_max_ratio (markers all of one size): a component
//                   larger than marker_max_ratio × reference is more than one marker
//                   can cover and is split by size as in (b) whatever its fill; a piece
//                   still that large (a round pair, or no second peak) is reported
//                   `merged`, never as one marker;
//   5. measure    — centroid weighted by the redness w = max(0, r − max(g, b)) over
//                   the piece and a one-pixel rim around it (the antialiased edge
//                   that missed the thresholds), so it is sub-pixel;
//   5b. edges     — with edge_points: the outline's sub-pixel points (src/edges.cpp);
//   6. filter     — area within [min_area_px, max_area_px], fill ≥ min_fill.
// Pixel coordinates follow geometry::Camera: (0, 0) is the centre of the top-left pixel.
#include <vector>

#include <opencv2/core.hpp>

namespace rocklab::track {

struct Detection {
  cv::Point2d centroid;  // px, redness-weighted, sub-pixel
  double area_px = 0;    // px², pixels of the (opened) mask in this marker
  double radius_px = 0;  // px, equivalent radius √(area / π)
  double fill = 0;       // area / area of the smallest enclosing circle [-]: 1 for a disc, ½ for two touching discs
  // More than one marker can cover (DetectorSettings::marker_max_ratio) and not cut
  // apart: two or more markers in one detection, whose centroid is none of theirs.
  bool merged = false;
  std::vector<cv::Point2f> edge_points;  // px, sub-pixel outline (only with DetectorSettings::edge_points)
};

struct DetectorSettings {
  // HSV thresholds (OpenCV 8-bit scale: hue 0..179, saturation and value 0..255).
  // Red is hue ≤ hue_low_max or hue ≥ hue_high_min.
  int hue_low_max = 10;
  int hue_high_min = 170;
  int saturation_min = 100;  // grey pebbles sit near 10, the painted markers above 200
  int value_min = 40;        // the shaded side of a marker still counts
  // Morphological open, square kernel side [px]; 0 or 1 = off.
  int open_kernel_px = 3;
  // Accepted marker size [px²], applied to each piece after splitting.
  double min_area_px = 12.0;
  double max_area_px = 20000.0;
  // Smallest accepted fill (area / enclosing-circle area) [-]: rejects slivers and threads.
  double min_fill = 0.35;
  // A component larger than split_ratio × the reference area and with a fill below
  // split_max_fill is split [-]; a big round blob is one big marker.
  double split_ratio = 1.8;
  double split_max_fill = 0.8;
  // A component that two or more predictions fall into is cut at them when its
  // area exceeds seeded_split_ratio × the reference [-] (two markers half hidden
  // behind each other still cover more than one; a single marker never does).
  double seeded_split_ratio = 1.25;
  // Area of one marker [px²]; 0 = the median component area of each frame (needs
  // a frame with mostly single markers; with one component nothing is ever split).
  double expected_area_px = 0.0;
  // With expected_area_px: the camera's focal length and principal point [px]; the
  // expected area then holds on the optical axis and grows off it as 1 / cos θ
  // (a marker at the image's edge covers more pixels than one at its centre).
  // 0 = the same everywhere.
  double focal_px = 0.0;
  cv::Point2d principal_point_px{0.0, 0.0};
  // Markers all of one size: the largest area one marker can cover, × the reference
  // [-]. A component above it holds two or more markers: split by size whatever its
  // fill (stage 4c), and a detection still above it after splitting is `merged`.
  // 0 = off (markers of any size; a big round blob is one big marker).
  double marker_max_ratio = 0.0;
  // Stage 5b: also give each detection the sub-pixel points of its outline (its
  // core pixels' steps to the unthresholded rim, placed by the two pixels'
  // redness), for the model-based position (shape_fit.h). Off: nothing is spent.
  bool edge_points = false;

  /// Throws std::invalid_argument naming the first invalid field ("detector.min_fill ...").
  void validate() const;
};

/// Red markers in a BGR image (CV_8UC3). Settings are validated; an image of
/// another type throws std::invalid_argument. No marker → an empty list.
/// Detections are in row-major order of their components (of their first pixel:
/// top to bottom, then left to right).
std::vector<Detection> detectMarkers(const cv::Mat& bgr, const DetectorSettings& settings = {});

/// The same, with the tracks' predicted pixels for this frame (Linker::predictions):
/// a component two or more predictions fall into is split at them (stage 4a).
/// `prediction_areas` (empty, or one a prediction; 0 = unknown): the area [px²]
/// that prediction's marker is known to cover. A component that holds exactly one
/// prediction of known area is one marker up to that area: stages 4b and 4c take
/// the larger of it and the reference (with markers of several sizes, a large one's
/// blob is not cut in two by the size of a small one).
std::vector<Detection> detectMarkers(const cv::Mat& bgr, const DetectorSettings& settings,
                                     const std::vector<cv::Point2d>& predictions,
                                     const std::vector<double>& prediction_areas = {});

}  // namespace rocklab::track
