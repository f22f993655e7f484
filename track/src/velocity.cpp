#include "rocklab/track/velocity.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "rocklab/track/plane.h"

namespace rocklab::track {

namespace {

// The trajectory from the reference time on: its first point interpolated at
// t_ref, then the samples after it. Unchanged when t_ref is NaN or not after the
// first sample; only the last sample when t_ref is after it.
void startAt(double t_ref, std::vector<geometry::Vec3>& world, std::vector<double>& time) {
  if (!(t_ref > time.front())) return;
  std::size_t k = 1;
  while (k < time.size() && time[k] <= t_ref) ++k;
  if (k == time.size()) {
    world = {world.back()};
    time = {time.back()};
    return;
  }
  const double f = (t_ref - time[k - 1]) / (time[k] - time[k - 1]);
  const geometry::Vec3 at = world[k - 1] + f * (world[k] - world[k - 1]);
  world.erase(world.begin(), world.begin() + static_cast<std::ptrdiff_t>(k));
  time.erase(time.begin(), time.begin() + static_cast<std::ptrdiff_t>(k));
  world.insert(world.begin(), at);
  time.insert(time.begin(), t_ref);
}

}  // namespace

MarkerVelocity velocityOverDistance(const std::vector<geometry::Vec3>& world_in, const std::vector<double>& time_in,
                                    const geometry::Vec3& direction, double distance, double onset,
                                    double reference_time) {
  std::vector<geometry::Vec3> world = world_in;
  std::vector<double> time = time_in;
  if (world.empty() || world.size() != time.size()) {
    std::ostringstream s;
    s << "velocityOverDistance: needs as many times as points, at least one (got " << world.size() << " points, "
      << time.size() << " times)";
    throw std::invalid_argument(s.str());
  }
  if (!(direction.norm() > 0.0) || !direction.allFinite())
    throw std::invalid_argument("velocityOverDistance: direction must be a finite non-zero vector");
  if (!(onset >= 0.0 && distance > onset) || !std::isfinite(distance)) {
    std::ostringstream s;
    s << "velocityOverDistance: needs 0 <= onset < distance (got onset " << onset << ", distance " << distance << ')';
    throw std::invalid_argument(s.str());
  }
  startAt(reference_time, world, time);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const geometry::Vec3 unit = direction.normalized();
  MarkerVelocity out;
  out.start_world = world.front();
  out.onset_time = out.end_time = out.velocity = nan;

  // Walk the samples; a level is crossed between sample k−1 (travel below it) and
  // sample k (travel at or above it): linear interpolation in time, as the engine does.
  auto crossing = [&](std::size_t k, double s0, double s1, double level) {
    const double f = (level - s0) / std::max(s1 - s0, 1e-300);
    return time[k - 1] + f * (time[k] - time[k - 1]);
  };
  double previous = 0.0;  // travel at the previous sample (the first sample has travel 0)
  if (onset == 0.0) out.onset_time = time.front();
  for (std::size_t k = 1; k < world.size(); ++k) {
    const double travel = (world[k] - world.front()).dot(unit);
    // The last upward crossing of the onset level: a marker that jitters about
    // its rest position (a blob centroid flickers as neighbours cover it) starts
    // when it leaves for good, not at its first flicker. Monotone travel: the same.
    if (onset > 0.0 && previous < onset && travel >= onset) out.onset_time = crossing(k, previous, travel, onset);
    if (travel >= distance) {
      out.end_time = crossing(k, previous, travel, distance);
      out.velocity = (distance - onset) / (out.end_time - out.onset_time);
      out.complete = true;
      break;
    }
    previous = travel;
  }
  return out;
}

MarkerVelocity trackVelocity(const Track& track, const geometry::Camera& camera, const geometry::Vec3& plane_point,
                             const geometry::Vec3& plane_normal, const geometry::Vec3& direction, double distance,
                             double onset, double reference_time) {
  std::vector<geometry::Vec3> world;
  std::vector<double> time;
  for (const TrackPoint& p : track.points)
    if (const auto x = pointToWorld(camera, p, plane_point, plane_normal)) {
      world.push_back(*x);
      time.push_back(p.time);
    }
  MarkerVelocity out;
  if (world.empty()) {  // no pixel meets the plane: nothing measured
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out.start_world = geometry::Vec3::Constant(nan);
    out.onset_time = out.end_time = out.velocity = nan;
  } else {
    out = velocityOverDistance(world, time, direction, distance, onset, reference_time);
  }
  // Points the measurement used: from the last one at or before the reference time
  // (interpolated from) to the first at or after the end of the travel.
  const std::vector<TrackPoint>& p = track.points;
  for (std::size_t k = 0; k < p.size() && !out.merged; ++k) {
    if (k + 1 < p.size() && p[k + 1].time <= reference_time) continue;  // before the reference
    if (out.complete && k > 0 && p[k - 1].time >= out.end_time) break;  // after the end
    out.merged = p[k].merged;
  }
  if (out.merged) {
    out.velocity = std::numeric_limits<double>::quiet_NaN();
    out.complete = false;
  }
  out.track_id = track.id;
  return out;
}

}  // namespace rocklab::track
