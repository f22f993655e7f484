#include "rocklab/track/evaluate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "rocklab/track/assignment.h"
#include "rocklab/track/plane.h"

namespace rocklab::track {

namespace {

// Running bias and RMS of one axis.
struct Moments {
  double sum = 0, sum2 = 0;
  int count = 0;
  void add(double e) { sum += e, sum2 += e * e, ++count; }
  AxisError error(std::string axis) const {
    return {std::move(axis), count ? sum / count : 0.0, count ? std::sqrt(sum2 / count) : 0.0};
  }
};

// Bin of the fractional pixel part f = x − round(x) in [−0.5, 0.5).
int subpixelBin(double x, int bins) {
  const double f = x - std::floor(x + 0.5);
  return std::clamp(static_cast<int>(std::floor((f + 0.5) * bins)), 0, bins - 1);
}

bool inView(const cv::Point2d& p, cv::Size size) {
  if (size.width <= 0 || size.height <= 0) return true;
  return p.x >= -0.5 && p.y >= -0.5 && p.x < size.width - 0.5 && p.y < size.height - 0.5;
}

}  // namespace

TrackingEvaluation evaluateTracks(const std::vector<Track>& tracks, const std::vector<TruthMarker>& truth,
                                  const geometry::Camera& camera, const geometry::Vec3& plane_point,
                                  const geometry::Vec3& plane_normal, const std::vector<WorldAxis>& axes,
                                  const EvaluationSettings& settings) {
  if (!(settings.match_distance_px > 0.0) || settings.subpixel_bins < 1)
    throw std::invalid_argument("evaluateTracks: match_distance_px must be > 0 px and subpixel_bins >= 1");
  // Frame → (marker, point) and frame → (track, point).
  std::map<int, std::vector<std::pair<std::size_t, const TruthPoint*>>> truth_at;
  for (std::size_t m = 0; m < truth.size(); ++m)
    for (const TruthPoint& p : truth[m].points)
      if (inView(p.pixel, settings.image_size)) truth_at[p.frame].emplace_back(m, &p);
  std::map<int, std::vector<std::pair<std::size_t, const TrackPoint*>>> track_at;
  for (std::size_t t = 0; t < tracks.size(); ++t)
    for (const TrackPoint& p : tracks[t].points)
      if (truth_at.count(p.frame)) track_at[p.frame].emplace_back(t, &p);

  TrackingEvaluation out;
  out.subpixel_u.assign(static_cast<std::size_t>(settings.subpixel_bins), 0);
  out.subpixel_v = out.subpixel_u;
  out.markers.resize(truth.size());
  for (std::size_t m = 0; m < truth.size(); ++m) out.markers[m].truth_id = truth[m].id;
  Moments u, v;
  std::vector<Moments> world(axes.size());
  std::vector<Moments> marker_distance(truth.size());  // per marker: |tracked − truth| in px
  std::vector<int> last_track(truth.size(), -1);    // track a marker was last paired with
  std::vector<int> last_marker(tracks.size(), -1);  // marker a track was last paired with
  const double gate2 = settings.match_distance_px * settings.match_distance_px;

  for (const auto& [frame, markers] : truth_at) {
    for (const auto& [m, p] : markers) ++out.markers[m].frames_in_view;
    const auto found = track_at.find(frame);
    if (found == track_at.end()) continue;
    const auto& points = found->second;
    const int rows = static_cast<int>(markers.size()), cols = static_cast<int>(points.size());
    // A pair beyond the gate costs more than all allowed pairs together: never chosen over one.
    const double forbidden = 4.0 * gate2 * (rows + cols + 1);
    std::vector<double> cost(static_cast<std::size_t>(rows) * cols);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const cv::Point2d d = points[c].second->pixel - markers[r].second->pixel;
        const double d2 = d.dot(d);
        cost[static_cast<std::size_t>(r) * cols + c] = d2 <= gate2 ? d2 : forbidden;
      }
    const std::vector<int> pairing = solveAssignment(cost, rows, cols);
    for (int r = 0; r < rows; ++r) {
      const int c = pairing[r];
      if (c < 0 || cost[static_cast<std::size_t>(r) * cols + c] > gate2) continue;
      const auto [m, truth_point] = markers[r];
      const auto [t, track_point] = points[c];
      MarkerScore& score = out.markers[m];
      ++score.frames_found;
      ++out.pairs;
      const int track_id = tracks[t].id;
      if (std::find(score.track_ids.begin(), score.track_ids.end(), track_id) == score.track_ids.end())
        score.track_ids.push_back(track_id);
      if (last_track[m] >= 0 && last_track[m] != static_cast<int>(t)) ++score.track_changes;
      if (last_marker[t] >= 0 && last_marker[t] != static_cast<int>(m)) ++out.identity_swaps;
      last_track[m] = static_cast<int>(t);
      last_marker[t] = static_cast<int>(m);
      u.add(track_point->pixel.x - truth_point->pixel.x);
      v.add(track_point->pixel.y - truth_point->pixel.y);
      marker_distance[m].add(cv::norm(track_point->pixel - truth_point->pixel));
      ++out.subpixel_u[static_cast<std::size_t>(subpixelBin(track_point->pixel.x, settings.subpixel_bins))];
      ++out.subpixel_v[static_cast<std::size_t>(subpixelBin(track_point->pixel.y, settings.subpixel_bins))];
      const std::optional<geometry::Vec3> x = pointToWorld(camera, *track_point, plane_point, plane_normal);
      if (x)
        for (std::size_t a = 0; a < axes.size(); ++a) world[a].add((*x - truth_point->world).dot(axes[a].direction));
      out.paired.push_back({frame, m, track_id, truth_point->pixel, track_point->pixel, truth_point->world, x});
    }
  }
  out.pixel_error = {u.error("u"), v.error("v")};
  for (std::size_t a = 0; a < axes.size(); ++a) out.world_error.push_back(world[a].error(axes[a].name));
  int in_view = 0, found_frames = 0;
  for (std::size_t m = 0; m < out.markers.size(); ++m) {
    MarkerScore& s = out.markers[m];
    s.rms_px = marker_distance[m].error("").rms;
    s.fraction_found = s.frames_in_view ? static_cast<double>(s.frames_found) / s.frames_in_view : 0.0;
    out.track_changes += s.track_changes;
    in_view += s.frames_in_view;
    found_frames += s.frames_found;
  }
  out.fraction_found = in_view ? static_cast<double>(found_frames) / in_view : 0.0;
  return out;
}

}  // namespace rocklab::track
