#include "rocklab/track/tracker.h"

namespace rocklab::track {

Tracker::Tracker(TrackerSettings settings) : settings_(settings), linker_(settings.link) {
  settings_.detector.validate();
  settings_.stitch.validate();
}

void Tracker::add(int frame, double time, const cv::Mat& bgr) {
  linker_.add(frame, time, detectMarkers(bgr, settings_.detector, linker_.predictions(frame, time)));
}

StitchResult Tracker::finish() const { return stitchTracks(linker_.tracks(), settings_.stitch, linker_.ambiguousEnds()); }

}  // namespace rocklab::track
