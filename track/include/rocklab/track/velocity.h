#pragma once
// A marker's velocity as the study defines it (experiments.md §c step 5): its mean
// velocity over the first `distance` (100 mm) of displacement along the base.
//
// travel s(t) = (x(t) − x(t_ref)) · direction, from the point at the reference time
//                       t_ref (interpolated between samples; the first sample when
//                       t_ref is NaN or earlier; samples before t_ref are not used),
//   onset_time  t_on  = last time s rises through `onset` (2 mm) before the end
//                       (the first, for monotone travel; later flickers of a blob are skipped),
//   end_time    t_end = first time s reaches `distance`,
// each interpolated linearly between the two samples around the crossing, and
//   velocity = (distance − onset) / (t_end − t_on).
// The onset keeps a marker upstream from being charged for the time the flow front
// took to reach it. This is the DEM ground truth of the chute experiment
// (experiments/src/chute_experiment.cpp, kOnset = 2 mm), point for point.
#include <limits>
#include <vector>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/vec.h"
#include "rocklab/track/link.h"

namespace rocklab::track {

struct MarkerVelocity {
  int track_id = -1;                              // −1 when computed from bare points
  geometry::Vec3 start_world = geometry::Vec3::Zero();  // m, point at the reference time (or the first)
  double onset_time = 0.0;  // s, NaN if the travel never reached onset
  double end_time = 0.0;    // s, NaN if it never reached distance
  double velocity = 0.0;    // m/s (or px/s for pixel points), NaN unless complete
  bool complete = false;    // the travel reached distance
  // trackVelocity: a point the measurement used (from the one before the reference
  // time to the end of the travel) was a merged detection (two or more markers in
  // one blob): the travel is not one marker's, velocity NaN and not complete.
  bool merged = false;
};

/// `world` and `time` have equal, non-zero length (std::invalid_argument otherwise);
/// time increases. `direction` is normalised here (must be non-zero); 0 ≤ onset < distance.
/// Units are the caller's: metres and seconds, or pixels and seconds.
MarkerVelocity velocityOverDistance(const std::vector<geometry::Vec3>& world, const std::vector<double>& time,
                                    const geometry::Vec3& direction, double distance, double onset,
                                    double reference_time = std::numeric_limits<double>::quiet_NaN());

/// The same for a track: each point is taken to the world (pointToWorld: its fitted
/// centre, else its pixel on the plane); points
/// whose ray misses the plane are skipped (none left: incomplete, every field NaN).
/// A track that was on a merged detection (TrackPoint::merged) while measured gives
/// no velocity (MarkerVelocity::merged). track_id is the track's.
MarkerVelocity trackVelocity(const Track& track, const geometry::Camera& camera, const geometry::Vec3& plane_point,
                             const geometry::Vec3& plane_normal, const geometry::Vec3& direction, double distance,
                             double onset, double reference_time = std::numeric_limits<double>::quiet_NaN());

}  // namespace rocklab::track
