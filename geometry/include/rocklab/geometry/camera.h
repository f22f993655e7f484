#pragma once
// The one camera model of rocklab: a pinhole with radial distortion, posed in the
// world. The renderer draws with it and the tracker measures with it.
//
// Convention (OpenCV's, so cv::projectPoints gives the same pixels):
//   camera frame   x right, y down, z forward (the camera looks along +z);
//   pose           x_cam = rotation * x_world + translation   (world → camera);
//   normalised     (x, y) = (X / Z, Y / Z);
//   distortion     s = 1 + k1 r² + k2 r⁴ with r² = x² + y²;  (x_d, y_d) = s (x, y);
//   pixel          u = fx x_d + cx,  v = fy y_d + cy.
// Pixel (0, 0) is the *centre* of the top-left pixel, so the image spans
// [-0.5, width - 0.5] × [-0.5, height - 0.5] and its middle is ((w - 1)/2, (h - 1)/2).
#include <Eigen/Core>

#include "rocklab/geometry/vec.h"

namespace rocklab::geometry {

using Vec2 = Eigen::Vector2d;

struct Camera {
  // Resolution [pixels].
  int width = 640;
  int height = 480;
  // Intrinsics [pixels]: focal lengths and principal point (OpenCV convention above).
  double fx = 800.0;
  double fy = 800.0;
  double cx = 319.5;
  double cy = 239.5;
  // Radial distortion coefficients (OpenCV k1, k2; p1 = p2 = k3 = 0) [-].
  double k1 = 0.0;
  double k2 = 0.0;
  // Pose, world → camera: x_cam = rotation * x_world + translation. rotation is a
  // proper rotation (orthonormal, det +1); translation in metres.
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
  // Timing: frames per second [1/s] and exposure (shutter open) time [s], 0 ≤ exposure ≤ 1/frameRate.
  double frameRate = 500.0;
  double exposureTime = 0.0;

  /// A camera of the given resolution and horizontal field of view [deg], square
  /// pixels, principal point in the middle of the image, at the world origin.
  static Camera withFieldOfView(int width, int height, double horizontalFovDeg);

  /// Throws std::invalid_argument naming the first invalid field ("camera.fx ...").
  void validate() const;

  /// Sets rotation and translation so that the camera sits at `eye`, looks at
  /// `target`, and `up` (world) points up in the image (−y). Throws
  /// std::invalid_argument when eye == target or up is parallel to the view.
  void lookAt(const Vec3& eye, const Vec3& target, const Vec3& up);

  /// Camera centre in the world [m].
  Vec3 position() const { return -rotation.transpose() * translation; }
  /// World point → camera frame [m].
  Vec3 toCamera(const Vec3& world) const { return rotation * world + translation; }
  /// World point → pixel, distortion applied. Needs toCamera(world).z() > 0.
  Vec2 project(const Vec3& world) const;
  /// Normalised undistorted (x, y) → normalised distorted (x_d, y_d).
  Vec2 distort(const Vec2& normalised) const;
  /// Inverse of distort (Newton on the radius). Throws std::domain_error when the
  /// distortion is not invertible at that radius (the lens folds over).
  Vec2 undistort(const Vec2& distorted) const;
  /// Unit direction (world frame) of the ray through a pixel, distortion removed.
  Vec3 pixelRay(const Vec2& pixel) const;
  bool hasDistortion() const { return k1 != 0.0 || k2 != 0.0; }
};

}  // namespace rocklab::geometry
