#include "rocklab/track/tracker.h"

#include <algorithm>
#include <utility>

namespace rocklab::track {

Tracker::Tracker(TrackerSettings settings) : settings_(settings), linker_(settings.link) {
  settings_.detector.validate();
  settings_.stitch.validate();
}

void Tracker::useShapeFit(ShapeFitter fitter) {
  useShapeFits({std::move(fitter)});
}

void Tracker::useShapeFits(std::vector<ShapeFitter> fitters) {
  fitters_ = std::move(fitters);
  settings_.detector.edge_points = !fitters_.empty();
}

void Tracker::add(int frame, double time, const cv::Mat& bgr) {
  // A track that has been cut in two by size knows its marker's area (below).
  std::vector<double> areas;
  if (!marker_areas_.empty())
    for (const int id : linker_.predictedTracks(frame)) {
      const auto known = marker_areas_.find(id);
      areas.push_back(known == marker_areas_.end() ? 0.0 : known->second);
    }
  const std::vector<Detection> detections =
      detectMarkers(bgr, settings_.detector, linker_.predictions(frame, time), areas);
  linker_.add(frame, time, detections);
  if (fitters_.empty()) return;
  // A seed older than the linker's reach (the marker was hidden) is still the best
  // guess of the orientation; the fit judges it by its residual.
  const std::vector<int> ids = linker_.lastTrackIds();
  struct Fitted {
    int id;             // track; -1 once withdrawn
    cv::Point2d pixel;  // fitted
    double area_px;     // of its detection, and of the pieces withdrawn into it
  };
  std::vector<Fitted> fitted;  // this frame's
  for (std::size_t i = 0; i < detections.size(); ++i) {
    const Detection& d = detections[i];
    const int id = ids[i];
    if (id < 0) continue;  // not linked (cannot happen: every detection extends or starts a track)
    const auto seed = seeds_.find(id);
    std::optional<MarkerPose> pose;
    std::size_t shape = seed == seeds_.end() ? 0 : seed->second.shape;
    if (seed != seeds_.end())
      pose =
          fitters_[shape].fit(d.edge_points, d.centroid, &seed->second.pose, seed->second.centroid);
    // A track's first fit searches every shape (one shape: its search); with several,
    // so does a seeded fit that had to search (the seed fit poorly: perhaps it had
    // the wrong shape).
    const bool several = fitters_.size() > 1;
    if (seed == seeds_.end() || (several && pose && pose->searched))
      if (const std::optional<ShapeChoice> best =
              fitBestShape(fitters_, d.edge_points, d.centroid)) {
        pose = best->pose;
        shape = best->shape;
        if (several) ++counts_.shape_choices;
      }
    if (!pose) {
      ++counts_.unfitted;
      continue;
    }
    ++counts_.fitted;
    if (pose->searched) ++counts_.searched;
    linker_.refineLastPoint(id, pose->pixel, pose->centre);
    seeds_[id] = {*pose, d.centroid, shape};
    fitted.push_back({id, pose->pixel, d.area_px});
  }
  // One marker fitted twice: the track with fewer points (the younger on a tie)
  // withdraws; the blob is then no longer cut at its prediction. The pieces were one
  // marker, so the track keeps their summed area as its marker's (the largest so
  // far): from the next frame on the detector does not cut a blob of that size that
  // holds only this track's prediction (a marker larger than the detector's one).
  if (settings_.duplicate_distance_px <= 0) return;
  const double limit2 = settings_.duplicate_distance_px * settings_.duplicate_distance_px;
  for (std::size_t a = 0; a < fitted.size(); ++a)
    for (std::size_t b = a + 1; b < fitted.size(); ++b) {
      if (fitted[a].id < 0 || fitted[b].id < 0) continue;  // already withdrawn
      const cv::Point2d d = fitted[a].pixel - fitted[b].pixel;
      if (d.dot(d) > limit2) continue;
      const std::size_t na = linker_.pointCount(fitted[a].id),
                        nb = linker_.pointCount(fitted[b].id);
      const bool a_goes = na < nb || (na == nb && fitted[a].id > fitted[b].id);
      Fitted& gone = a_goes ? fitted[a] : fitted[b];
      Fitted& kept = a_goes ? fitted[b] : fitted[a];
      linker_.withdraw(gone.id);
      seeds_.erase(gone.id);
      marker_areas_.erase(gone.id);
      ++counts_.duplicates;
      kept.area_px += gone.area_px;
      double& known = marker_areas_[kept.id];
      known = std::max(known, kept.area_px);
      gone.id = -1;
    }
}

StitchResult Tracker::finish() const {
  return stitchTracks(linker_.tracks(), settings_.stitch, linker_.ambiguousEnds());
}

}  // namespace rocklab::track
