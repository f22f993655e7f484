#pragma once
// How a tracker did against known positions (the DEM truth, or drawn test frames):
// the figures a tracking study reports (trackpy, TrackMate users compute them by hand).
//
// Frame by frame, the truth markers in view and the track points of that frame are
// paired by least total squared distance (Hungarian), a pair at most
// match_distance_px apart. Over all pairs:
//   bias, RMS      — per image axis (u, v) in px, and per world axis (the tracked
//                    pixel taken to the plane, minus the true world point) in m;
//   sub-pixel      — histogram of the tracked positions' fractional pixel part
//                    (u − round(u), v − round(v), in [−0.5, 0.5)): flat for an unbiased
//                    centroid, peaked at 0 when it locks to pixel centres;
//   found          — per marker, the frames it was paired in over the frames it was
//                    in view (its true pixel inside the image);
//   identity swaps — a track paired with one marker and next with another (an exchange
//                    of two markers' tracks counts two); track changes: a marker paired
//                    with another track than the last (a new track after a loss, or a swap).
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/vec.h"
#include "rocklab/track/link.h"

namespace rocklab::track {

struct TruthPoint {
  int frame = 0;
  cv::Point2d pixel;                                // px, the true camera's projection
  geometry::Vec3 world = geometry::Vec3::Zero();    // m
};

struct TruthMarker {
  int id = 0;
  std::vector<TruthPoint> points;  // by increasing frame
};

struct WorldAxis {
  std::string name;                                 // "x"
  geometry::Vec3 direction = geometry::Vec3::UnitX();  // unit, world frame
};

struct EvaluationSettings {
  double match_distance_px = 10.0;  // px: farthest a track point may be from the truth and still be it
  int subpixel_bins = 10;           // bins over [−0.5, 0.5) px
  cv::Size image_size;              // px: a truth point outside is out of view (empty size: all in view)
};

struct AxisError {
  std::string axis;
  double bias = 0.0;  // mean of tracked − truth
  double rms = 0.0;   // root mean square of tracked − truth (bias included)
};

struct MarkerScore {
  int truth_id = 0;
  int frames_in_view = 0;
  int frames_found = 0;
  double fraction_found = 0.0;  // frames_found / frames_in_view (0 when never in view)
  int track_changes = 0;
  std::vector<int> track_ids;   // tracks it was paired with, in order of first pairing
  double rms_px = 0.0;          // px, RMS distance tracked − truth over its pairs (0 when none)
};

/// One truth–track pair of one frame: the truth beside what the tracker said.
struct PairedPoint {
  int frame = 0;
  std::size_t marker = 0;  // index into the truth
  int track_id = -1;
  cv::Point2d truth_pixel, tracked_pixel;  // px
  geometry::Vec3 truth_world = geometry::Vec3::Zero();  // m
  std::optional<geometry::Vec3> tracked_world;           // m; none when the ray misses the plane
};

struct TrackingEvaluation {
  int pairs = 0;                       // truth-track pairs over all frames
  std::vector<AxisError> pixel_error;  // u, v in px
  std::vector<AxisError> world_error;  // one per WorldAxis, m
  std::vector<int> subpixel_u, subpixel_v;  // counts per bin, bin k from −0.5 + k / bins
  std::vector<MarkerScore> markers;    // in the order of the truth
  int identity_swaps = 0;
  int track_changes = 0;
  double fraction_found = 0.0;         // all markers' frames found / frames in view
  std::vector<PairedPoint> paired;     // every pair, by frame then truth order
};

/// `camera`, `plane_point`, `plane_normal`: the tracker's own (pixelToPlane), for the
/// world errors; a point whose ray misses the plane counts in the pixel errors only.
TrackingEvaluation evaluateTracks(const std::vector<Track>& tracks, const std::vector<TruthMarker>& truth,
                                  const geometry::Camera& camera, const geometry::Vec3& plane_point,
                                  const geometry::Vec3& plane_normal, const std::vector<WorldAxis>& axes,
                                  const EvaluationSettings& settings);

}  // namespace rocklab::track
