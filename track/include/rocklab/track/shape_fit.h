#pragma once
// Model-based marker position: the lab knows the shape of its marker pebbles (the
// clump's balls) and that they touch the Perspex wall, so instead of the centroid
// of what shows, the tracker fits the projected outline of the clump to the
// sub-pixel edge points of the marker's blob (detect.h, DetectorSettings::edge_points)
// and reports the projection of the clump's centre.
//
// The model (src/shape_fit.cpp):
//   pose       orientation R (body → world) and the centre's position along the
//              wall (two coordinates); the centre's distance from the wall follows
//              from R: the ball nearest the wall touches it,
//                  h(R) = max_k (r_k − n · R o_k),
//              so the depth, which the outline's size could not give to the
//              needed 0.1 mm, comes from the orientation;
//   outline    each ball's exact perspective silhouette (an ellipse, stretched
//              radially off the optical axis), distortion applied at its centre;
//              the clump's outline is their union;
//   residual   per edge point: its signed distance to the union, min_k over the
//              balls of the distance to ball k's ellipse along its ray from the
//              ellipse centre; a Huber loss (scale robust_px) keeps the edges of
//              a neighbour that hides part of the marker from pulling it;
//   solver     Levenberg–Marquardt (Eigen's unsupported LevenbergMarquardt;
//              forward-difference Jacobian with each edge point kept on its
//              nearest ball) over 5 parameters (2 along the wall, 3 of a rotation
//              vector about the start orientation).
// Seeding: a track's fit starts from its pose in the previous frame (one LM run,
// no orientation switches between frames); a track's first frame, or a seeded
// fit whose RMS residual exceeds reseed_rms_px and reseed_ratio times the seed's
// (the fit fell into another orientation), searches start_orientations
// orientations (their cost at the blob's centroid, then LM from the best
// refined_starts) and keeps the best (the seeded one included).
#include <optional>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/vec.h"
#include "rocklab/track/link.h"

namespace rocklab::track {

/// What the lab knows of its markers: the clump (every marker the same shape) and
/// the wall they touch.
struct MarkerModel {
  std::vector<geometry::Sphere> balls;  // m, body frame; the origin is the point tracked (centre of mass)
  geometry::Vec3 wall_point = geometry::Vec3::Zero();
  geometry::Vec3 wall_normal = geometry::Vec3::UnitY();  // from the wall into the bed (away from the camera)

  /// Throws std::invalid_argument naming the first invalid field ("marker_model.balls ...").
  void validate() const;
};

struct MarkerPose {
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body → world
  geometry::Vec3 centre = geometry::Vec3::Zero();                    // m, world: the body origin
  cv::Point2d pixel;     // px, the centre's projection
  double rms_px = 0.0;   // RMS of the (Huber-limited) edge residuals
  int edge_points = 0;
  bool searched = false;  // the multi-start search ran (first frame or a poor seeded fit)
};

struct ShapeFitSettings {
  int start_orientations = 112;  // orientations tried when there is no seed (or it fit poorly)
  int refined_starts = 6;        // of those, the lowest-cost ones refined by LM
  double reseed_rms_px = 0.6;    // a seeded fit with a larger RMS residual [px]...
  double reseed_ratio = 1.5;     // ...and this many times its seed's searches again
  double robust_px = 1.0;        // Huber scale of the edge residuals [px]
  int max_evaluations = 400;     // LM function evaluations per run
  int min_edge_points = 12;      // fewer: no fit (the centroid stands)
  int max_edge_points = 64;      // more: every k-th is used

  /// Throws std::invalid_argument naming the first invalid field ("shape_fit.robust_px ...").
  void validate() const;
};

class ShapeFitter {
 public:
  ShapeFitter(const geometry::Camera& camera, MarkerModel model, ShapeFitSettings settings = {});

  /// The pose whose outline fits `edges` (px) best. With `seed` (the track's previous
  /// pose) LM starts there, the position moved by the blob's shift: centroid −
  /// seed_centroid; without it, or when the seeded fit is poor, the multi-start
  /// search runs from `centroid`. Empty with fewer than min_edge_points edges or
  /// when no start converges in front of the camera.
  std::optional<MarkerPose> fit(const std::vector<cv::Point2f>& edges, cv::Point2d centroid,
                                const MarkerPose* seed = nullptr, cv::Point2d seed_centroid = {}) const;

  /// The pose of orientation `orientation` whose centre lies on the ray through
  /// `pixel`, touching the wall (no fit); empty when the ray misses the wall's side.
  std::optional<MarkerPose> poseThrough(const Eigen::Quaterniond& orientation, cv::Point2d pixel) const;

  /// Distance of the centre from the wall when the clump touches it in this orientation [m].
  double wallDistance(const Eigen::Quaterniond& orientation) const;

  /// The start orientations of the search (deterministic).
  const std::vector<Eigen::Quaterniond>& startOrientations() const { return starts_; }
  const ShapeFitSettings& settings() const { return settings_; }
  const MarkerModel& model() const { return model_; }

 private:
  MarkerPose refine(const std::vector<cv::Point2f>& edges, const MarkerPose& start) const;

  geometry::Camera camera_;
  MarkerModel model_;
  ShapeFitSettings settings_;
  geometry::Vec3 along_u_, along_v_;  // unit vectors spanning the wall
  std::vector<Eigen::Quaterniond> starts_;
};

/// A blob fitted by the shape of each of several markers (a chute whose markers are
/// clumps of several sizes): the shape whose fit leaves the smallest edge residual
/// (MarkerPose::rms_px), and its pose. A wrong shape cannot match the outline at
/// the depth its contact with the wall fixes, so its residual stays larger.
struct ShapeChoice {
  std::size_t shape = 0;  // index into the fitters
  MarkerPose pose;
};
/// Each fitter's fit (fit(), no seed: the multi-start search); empty when none fits.
std::optional<ShapeChoice> fitBestShape(const std::vector<ShapeFitter>& fitters, const std::vector<cv::Point2f>& edges,
                                        cv::Point2d centroid);

/// The fitted depths of each track (TrackPoint::centre's distance from the wall)
/// replaced by their running median over ±half_window points, each centre moved
/// along its pixel's ray to that depth: a nearly flat clump's tilt, and so its
/// depth, is ill-determined frame by frame (its outline shortens only as the
/// cosine of the tilt), while the marker's depth changes slowly. Points without a
/// centre are left alone.
void smoothFittedDepths(std::vector<Track>& tracks, const geometry::Camera& camera, const MarkerModel& model,
                        int half_window);

}  // namespace rocklab::track
