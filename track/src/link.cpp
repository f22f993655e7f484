#include "rocklab/track/link.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "rocklab/track/assignment.h"

namespace rocklab::track {

namespace {

// Where a point was detected: the linker links centroids to centroids, also when
// the reported position is a shape fit's.
cv::Point2d detectedAt(const TrackPoint& p) { return std::isnan(p.detected.x) ? p.pixel : p.detected; }

// Constant-velocity prediction of a track's detected pixel at `time`.
cv::Point2d predict(const Track& track, double time) {
  const TrackPoint& last = track.points.back();
  if (track.points.size() < 2) return detectedAt(last);
  const TrackPoint& prev = track.points[track.points.size() - 2];
  const cv::Point2d velocity = (detectedAt(last) - detectedAt(prev)) / (last.time - prev.time);  // px/s
  return detectedAt(last) + velocity * (time - last.time);
}

double squaredDistance(const cv::Point2d& a, const cv::Point2d& b) {
  const cv::Point2d d = a - b;
  return d.dot(d);
}

}  // namespace

void LinkSettings::validate() const {
  if (!(max_distance_px > 0.0) || !std::isfinite(max_distance_px)) {
    std::ostringstream s;
    s << "link.max_distance_px must be a finite distance > 0 px (got " << max_distance_px << ')';
    throw std::invalid_argument(s.str());
  }
  if (!(ambiguity_ratio > 0.0 && ambiguity_ratio <= 1.0)) {
    std::ostringstream s;
    s << "link.ambiguity_ratio must be in (0, 1] (got " << ambiguity_ratio << ')';
    throw std::invalid_argument(s.str());
  }
  if (max_missed_frames < 0)
    throw std::invalid_argument("link.max_missed_frames must be >= 0 (got " + std::to_string(max_missed_frames) + ")");
}

Linker::Linker(LinkSettings settings) : settings_(settings) { settings_.validate(); }

void Linker::add(int frame, double time, const std::vector<Detection>& detections) {
  if (started_ && !(frame > last_frame_ && time > last_time_)) {
    std::ostringstream s;
    s << "Linker::add: frames and times must increase (frame " << frame << " at " << time << " s after frame "
      << last_frame_ << " at " << last_time_ << " s)";
    throw std::invalid_argument(s.str());
  }
  started_ = true;
  last_track_ids_.assign(detections.size(), -1);
  last_frame_ = frame;
  last_time_ = time;

  // 1. retire tracks unseen for more than max_missed_frames frames.
  std::erase_if(active_, [&](int id) { return retired(id, frame); });

  // 2. predict, 3. cost: squared distance, gated.
  const int n = static_cast<int>(active_.size()), m = static_cast<int>(detections.size());
  const double gate2 = settings_.max_distance_px * settings_.max_distance_px;
  std::vector<double> distance2(static_cast<std::size_t>(n) * m);
  for (int i = 0; i < n; ++i) {
    const cv::Point2d p = predict(tracks_[active_[i]], time);
    for (int j = 0; j < m; ++j) distance2[static_cast<std::size_t>(i) * m + j] = squaredDistance(p, detections[j].centroid);
  }

  // 4. assign: detection of each active track, −1 = missed this frame.
  std::vector<int> match(n, -1);
  if (n > 0 && m > 0) {
    if (settings_.assignment == LinkSettings::Assignment::Greedy) {
      match = greedyAssignment(distance2, n, m, gate2);
    } else {
      // Augmented (n + m) square matrix; a forbidden pair costs more than any
      // solution without one (at most (n + m) gate²), so none is ever chosen.
      const int size = n + m;
      const double forbidden = 4.0 * gate2 * (size + 1);
      std::vector<double> cost(static_cast<std::size_t>(size) * size, forbidden);
      auto at = [&](int r, int c) -> double& { return cost[static_cast<std::size_t>(r) * size + c]; };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < m; ++j) {
          const double d2 = distance2[static_cast<std::size_t>(i) * m + j];
          if (d2 <= gate2) at(i, j) = d2;
        }
      for (int i = 0; i < n; ++i) at(i, m + i) = gate2;  // track i missed
      for (int j = 0; j < m; ++j) at(n + j, j) = gate2;  // detection j starts a track
      for (int r = n; r < size; ++r)
        for (int c = m; c < size; ++c) at(r, c) = 0.0;    // dummy ↔ dummy
      const std::vector<int> solution = solveAssignment(cost, size, size);
      for (int i = 0; i < n; ++i)
        if (solution[i] < m) match[i] = solution[i];
    }
  }

  // 5. update: matched tracks grow, the other detections start tracks; a track
  // whose match is not clearly its nearest detection ends.
  std::vector<char> used(m, 0), closed(n, 0);
  auto pointOf = [&](const Detection& d) {
    TrackPoint point{frame, time, d.centroid, d.centroid};
    point.merged = d.merged;
    return point;
  };
  const double ratio2 = settings_.ambiguity_ratio * settings_.ambiguity_ratio;
  for (int i = 0; i < n; ++i) {
    if (match[i] < 0) continue;
    if (ratio2 < 1.0) {
      const double* row = &distance2[static_cast<std::size_t>(i) * m];
      const double mine = row[match[i]];
      bool ambiguous = false;
      for (int j = 0; j < m && !ambiguous; ++j)  // another detection about as near
        ambiguous = j != match[i] && row[j] <= gate2 && mine > ratio2 * row[j];
      for (int k = 0; k < n && !ambiguous; ++k) {  // another track about as near its detection
        const double other = distance2[static_cast<std::size_t>(k) * m + match[i]];
        ambiguous = k != i && other <= gate2 && mine > ratio2 * other;
      }
      if (ambiguous) {
        closed[i] = 1;
        ambiguous_ends_.push_back(active_[i]);
        continue;
      }
    }
    tracks_[active_[i]].points.push_back(pointOf(detections[match[i]]));
    used[match[i]] = 1;
    last_track_ids_[static_cast<std::size_t>(match[i])] = active_[i];
  }
  for (int i = n - 1; i >= 0; --i)
    if (closed[i]) active_.erase(active_.begin() + i);
  for (int j = 0; j < m; ++j) {
    if (used[j]) continue;
    const int id = static_cast<int>(tracks_.size());
    tracks_.push_back({id, {pointOf(detections[j])}});
    active_.push_back(id);
    last_track_ids_[static_cast<std::size_t>(j)] = id;
  }
}

bool Linker::retired(int id, int frame) const {
  return frame - tracks_[static_cast<std::size_t>(id)].points.back().frame - 1 > settings_.max_missed_frames;
}

std::vector<cv::Point2d> Linker::predictions(int frame, double time) const {
  std::vector<cv::Point2d> out;
  for (const int id : predictedTracks(frame))
    out.push_back(predict(tracks_[static_cast<std::size_t>(id)], time));
  return out;
}

std::vector<int> Linker::predictedTracks(int frame) const {
  std::vector<int> out;
  out.reserve(active_.size());
  for (const int id : active_)
    if (!retired(id, frame)) out.push_back(id);
  return out;
}

std::vector<Track> Linker::tracks() const {
  std::vector<Track> out;
  out.reserve(tracks_.size());
  for (const Track& t : tracks_)
    if (!t.points.empty()) out.push_back(t);
  return out;
}

void Linker::withdraw(int id) {
  if (id < 0 || id >= static_cast<int>(tracks_.size()) || tracks_[static_cast<std::size_t>(id)].points.empty() ||
      tracks_[static_cast<std::size_t>(id)].points.back().frame != last_frame_)
    throw std::invalid_argument("Linker::withdraw: track " + std::to_string(id) + " has no point in the last frame");
  tracks_[static_cast<std::size_t>(id)].points.pop_back();
  std::erase(active_, id);
}

void Linker::refineLastPoint(int id, cv::Point2d pixel, const geometry::Vec3& centre) {
  if (id < 0 || id >= static_cast<int>(tracks_.size()) || tracks_[static_cast<std::size_t>(id)].points.empty() ||
      tracks_[static_cast<std::size_t>(id)].points.back().frame != last_frame_)
    throw std::invalid_argument("Linker::refineLastPoint: track " + std::to_string(id) + " has no point in the last frame");
  TrackPoint& p = tracks_[static_cast<std::size_t>(id)].points.back();
  p.pixel = pixel;
  p.centre = centre;
}

}  // namespace rocklab::track
