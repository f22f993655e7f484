#include "analysis/marker_tracking.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace rocklab::experiments {

MarkerTracking::MarkerTracking(const geometry::Camera& camera, double onset, double measure_distance)
    : camera_(camera), onset_(onset), measure_distance_(measure_distance) {}

void MarkerTracking::setMarkers(double plane_y, double radius) {
  plane_y_ = plane_y;
  // Projected disc of the marker at the plane's depth along the optical axis.
  const geometry::Vec3 centre_on_plane(camera_.position().x(), plane_y, camera_.position().z());
  const double depth = std::abs(camera_.toCamera(centre_on_plane).z());
  const double px_per_m = 0.5 * (camera_.fx + camera_.fy) / std::max(depth, 1e-9);
  const double r_px = px_per_m * radius;
  marker_radius_px_ = r_px;
  track::TrackerSettings s;
  s.detector.expected_area_px = 3.14159265358979 * r_px * r_px;
  // A lone marker pebble (a clump) seen side on covers up to about 1.3 times the disc
  // of its equivalent sphere (demo: 595-628 px² against 494), so a blob is cut at two
  // tracks' predictions only above kSeededSplitAreas of that disc; at the detector's
  // 1.25 a lone clump that had shown as two blobs for a while kept a phantom second
  // track, and the marker's identity was split (demo: 19 of 20 markers, 30 tracks,
  // 16 unresolved; at 1.3-1.5: 20 of 20, 26 tracks, 7 unresolved; at 1.6 the same markers).
  constexpr double kSeededSplitAreas = 1.4;
  s.detector.seeded_split_ratio = kSeededSplitAreas;
  // The same bound decides without predictions (issue 25): a blob over it is more
  // than one marker can cover and is split by size whatever its fill (the area
  // rule's 1.8 missed a pair of touching markers whose noisy mask covered 1.75 discs
  // at sensor noise 15, fill 0.40, so one track started on both); one that cannot be
  // split is reported merged and gives no velocity. The disc's area holds on the
  // optical axis and grows off it as a ball's image does (1 / cos θ: 1.15 at the
  // demo's left edge, where a lone marker covered 1.39 discs).
  s.detector.marker_max_ratio = kSeededSplitAreas;
  // A blob under a tenth of one marker's disc is a speck, not a marker to measure
  // (the shape fit has too little outline): at sensor noise 15 a 19 px speck where
  // two touching markers meet (a disc covers 494 px²) started a track whose
  // prediction then cut one of them in two for three frames, and that marker's
  // track was lost (issue 25: 19 of 20 markers at sigma 15).
  constexpr double kMinMarkerFraction = 0.1;
  s.detector.min_area_px = std::max(s.detector.min_area_px, kMinMarkerFraction * s.detector.expected_area_px);
  s.detector.focal_px = 0.5 * (camera_.fx + camera_.fy);
  s.detector.principal_point_px = {camera_.cx, camera_.cy};
  // Gate: what a marker can move between two frames beyond the constant-velocity
  // prediction (up to kMaxSpeed for one frame) plus centroid jitter (up to a radius:
  // the visible part of a clump changes as it turns), so a track does not jump to a
  // touching neighbour one diameter away.
  // A marker hidden for a moment (it turns its paint away, a neighbour covers it) is
  // re-found by the linker for up to kMaxHidden; longer, up to kMaxStitchGap, its
  // track is stitched to one that starts within kStitchRadii marker radii of where
  // it was heading (least-squares velocity of its last kStitchVelocityTime), unless
  // two candidates are about as near (then both are reported unresolved).
  constexpr double kMaxSpeed = 1.0;         // m/s: faster than any marker of the chute
  constexpr double kMaxHidden = 0.02;       // s
  constexpr double kMaxStitchGap = 0.15;    // s
  constexpr double kStitchRadii = 1.0;      // marker radii
  constexpr double kStitchVelocityTime = 0.02;  // s
  // A track whose detection is not at most kAmbiguityRatio times as far as the next
  // one (its blob came apart and its prediction lies between the pieces) ends there,
  // as does a stitch with a rival about as near: unresolved, never a guess.
  constexpr double kAmbiguityRatio = 0.6;
  s.link.max_distance_px = r_px + px_per_m * kMaxSpeed / camera_.frameRate;
  s.link.ambiguity_ratio = kAmbiguityRatio;
  s.link.max_missed_frames = std::max(3, static_cast<int>(std::lround(kMaxHidden * camera_.frameRate)));
  s.stitch.max_gap_frames = static_cast<int>(std::lround(kMaxStitchGap * camera_.frameRate));
  s.stitch.max_distance_px = kStitchRadii * r_px;
  s.stitch.ambiguity_ratio = kAmbiguityRatio;
  s.stitch.velocity_points = std::max(2, static_cast<int>(std::lround(kStitchVelocityTime * camera_.frameRate)));
  // With the shape fit, a track whose fitted centre repeats a longer track's within
  // kDuplicateRadii marker radii follows the same marker (a blob cut in two) and
  // ends there; two markers' centres are at least a clump's width apart.
  constexpr double kDuplicateRadii = 0.5;
  s.duplicate_distance_px = kDuplicateRadii * r_px;
  tracker_ = std::make_unique<track::Tracker>(s);
}

void MarkerTracking::useShapeFit(const std::vector<std::vector<geometry::Sphere>>& shapes) {
  std::vector<track::ShapeFitter> fitters;
  for (const std::vector<geometry::Sphere>& balls : shapes) {
    track::MarkerModel model;
    model.balls = balls;
    model.wall_point = geometry::Vec3::Zero();
    model.wall_normal = geometry::Vec3::UnitY();
    fitters.emplace_back(camera_, model);
  }
  if (fitters.empty()) return;
  shape_model_ = fitters.front().model();  // the wall, which every shape shares (smoothFittedDepths)
  shape_count_ = fitters.size();
  tracker_->useShapeFits(std::move(fitters));
}

void MarkerTracking::addFrame(std::uint64_t frame, double time, const cv::Mat& bgr) {
  const auto t0 = std::chrono::steady_clock::now();
  tracker_->add(static_cast<int>(frame), time, bgr);
  frames_.emplace_back(static_cast<int>(frame), time);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

MarkerTracking::Result MarkerTracking::finish() const {
  Result r;
  const auto t0 = std::chrono::steady_clock::now();
  track::StitchResult stitched = tracker_->finish();
  r.tracks = std::move(stitched.tracks);
  r.joins = std::move(stitched.joins);
  r.unresolved = std::move(stitched.unresolved);
  auto velocitiesOf = [&](const std::vector<track::Track>& tracks) {
    std::vector<track::MarkerVelocity> v;
    for (const track::Track& t : tracks)
      v.push_back(track::trackVelocity(t, camera_, planePoint(), geometry::Vec3::UnitY(), -geometry::Vec3::UnitX(),
                                       measure_distance_, onset_, reference_time_));
    return v;
  };
  if (shape_model_) {
    r.shape_fit = true;
    r.shapes = shape_count_;
    r.shape_fit_counts = tracker_->shapeFitCounts();
    std::vector<track::Track> on_plane = r.tracks;
    for (track::Track& t : on_plane)
      for (track::TrackPoint& p : t.points) p.centre = geometry::Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    r.depth_variants.emplace_back("fitted depth per frame", velocitiesOf(r.tracks));
    r.depth_variants.emplace_back("marker plane", velocitiesOf(on_plane));
    // The depth a marker's velocity is taken at: its fitted depth, as the running
    // median over kDepthSmoothing either side (a nearly flat clump's tilt is
    // ill-determined frame by frame; the marker turns slowly). The positions are not
    // smoothed: a local quadratic over 10 ms either side made the demo worse (RMS
    // 0.60 % against 0.50 %, max 1.87 % against 1.51 %: it rounds off the start of
    // the motion at the gate opening).
    constexpr double kDepthSmoothing = 0.025;  // s
    track::smoothFittedDepths(r.tracks, camera_, *shape_model_,
                              std::max(1, static_cast<int>(std::lround(kDepthSmoothing * camera_.frameRate))));
  }
  r.velocities = velocitiesOf(r.tracks);
  r.frames = frames_;
  r.seconds = seconds_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace rocklab::experiments
