#pragma once
// The whole tracker on a film: per frame, the linker's predictions seed the
// detector's split of merged blobs (detect.h, 4a), the detections are linked
// (link.h); at the end, tracks broken by a gap are stitched (stitch.h).
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/track/detect.h"
#include "rocklab/track/link.h"
#include "rocklab/track/stitch.h"

namespace rocklab::track {

struct TrackerSettings {
  DetectorSettings detector;
  LinkSettings link;
  StitchSettings stitch;
};

class Tracker {
 public:
  explicit Tracker(TrackerSettings settings = {});
  /// One BGR frame; frames and times increase (Linker::add).
  void add(int frame, double time, const cv::Mat& bgr);
  /// The linker's tracks, stitched.
  StitchResult finish() const;
  const TrackerSettings& settings() const { return settings_; }
  /// The tracks before stitching, and which ended at an ambiguous match.
  const Linker& linker() const { return linker_; }

 private:
  TrackerSettings settings_;
  Linker linker_;
};

}  // namespace rocklab::track
