#pragma once
// The whole tracker on a film: per frame, the linker's predictions seed the
// detector's split of merged blobs (detect.h, 4a), the detections are linked
// (link.h), and with a shape fit (useShapeFit) each linked detection's position
// becomes the model-based one (shape_fit.h), seeded from its track's pose in the
// previous frame (with several marker shapes, a track's first fit tries each and
// keeps the best, fitBestShape, and its later fits use that shape), and a track
// whose fit repeats another's ends (one marker's blob cut in two; the other track
// keeps both pieces' area as its marker's, so its blob is not cut by size again); at the end,
// tracks broken by a gap are stitched (stitch.h).
#include <optional>
#include <unordered_map>
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/track/detect.h"
#include "rocklab/track/link.h"
#include "rocklab/track/shape_fit.h"
#include "rocklab/track/stitch.h"

namespace rocklab::track {

struct TrackerSettings {
  DetectorSettings detector;
  LinkSettings link;
  StitchSettings stitch;
  // With the shape fit: two detections of one frame whose fitted centres lie within
  // this distance are one marker (its blob was cut in two and both pieces fit the
  // same clump; two markers' centres are a clump's width apart at least): the track
  // with fewer points gives its point up and ends (Linker::withdraw) [px]; 0 = never.
  double duplicate_distance_px = 0.0;
};

class Tracker {
 public:
  explicit Tracker(TrackerSettings settings = {});
  /// Model-based positions from now on: the detector gives edge points, every
  /// linked detection with enough of them is fitted, by one marker shape or by the
  /// best of several (one fitter each).
  void useShapeFit(ShapeFitter fitter);
  void useShapeFits(std::vector<ShapeFitter> fitters);
  /// One BGR frame; frames and times increase (Linker::add).
  void add(int frame, double time, const cv::Mat& bgr);

  struct ShapeFitCounts {
    long fitted = 0;     // detections whose position is the fit's
    long searched = 0;   // of those, fits that ran the multi-start search
    long shape_choices = 0;  // of those, fits that chose among several shapes
    long unfitted = 0;   // detections left at their centroid (too few edge points, no convergence)
    long duplicates = 0; // detections withdrawn: their fit repeated another track's (duplicate_distance_px)
  };
  const ShapeFitCounts& shapeFitCounts() const { return counts_; }
  /// The linker's tracks, stitched.
  StitchResult finish() const;
  const TrackerSettings& settings() const { return settings_; }
  /// The tracks before stitching, and which ended at an ambiguous match.
  const Linker& linker() const { return linker_; }

 private:
  struct Seed {
    MarkerPose pose;
    cv::Point2d centroid;  // px, the detection's centroid the pose was fitted to
    std::size_t shape = 0;  // the fitter of the track's shape
  };
  TrackerSettings settings_;
  Linker linker_;
  std::vector<ShapeFitter> fitters_;  // none: centroids
  std::unordered_map<int, Seed> seeds_;  // by track id: its last fitted pose
  // By track id: the area its marker covers [px²], learnt when its blob was cut in
  // two and both pieces fit it (the duplicate rule); the detector's size rules then
  // leave a blob of that size with its prediction whole.
  std::unordered_map<int, double> marker_areas_;
  ShapeFitCounts counts_;
};

}  // namespace rocklab::track
