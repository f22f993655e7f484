#pragma once
// A wall's pose at the current time and its contact query. Internal.
//
// Geometry is stored in the wall's rest frame (Model::walls); a moving wall maps
// the ball centre into that frame (bodyFromWorld), finds the closest point there
// and maps the result back (worldFromBody). Static walls skip both maps.
#include <cmath>
#include <numbers>

#include "rocklab/geometry/closest_point.h"
#include "rocklab/sim/model.h"
#include "rocklab/sim/wall_motion.h"

namespace rocklab::sim::detail {

using geometry::Vec3;

struct WallContact {
  Vec3 normal;     // unit, from the ball centre towards the wall
  double overlap;  // m, > 0
};

class WallRuntime {
 public:
  bool active = false;

  void setup(const Wall& w) {
    is_static_ = w.motion.isStatic();
    if (w.shape == WallShape::Plane) {
      unit_normal_ = w.normal.normalized();
    } else if (w.shape == WallShape::Polygon) {
      unit_normal_ = polygonNormal(w.vertices);
      for (const Vec3& v : w.vertices) extent_ = std::max(extent_, (v - w.motion.pivot).norm());
    } else {
      unit_normal_ = Vec3::UnitZ();
      for (const Vec3& v : w.mesh.vertices) extent_ = std::max(extent_, (v - w.motion.pivot).norm());
    }
  }

  /// Pose and activity at time t.
  void update(const Wall& w, double t) {
    active = w.activeAt(t);
    if (is_static_) return;
    const WallPose pose = wallPoseAt(w.motion, t);
    translation_ = pose.translation;
    velocity_ = pose.velocity;
    omega_ = pose.omega;
    angle_ = pose.angle;
    rotation_ = pose.rotation;
    centre_ = pose.pivot + translation_;
    pivot_ = pose.pivot;
  }

  void setReference() {
    ref_translation_ = translation_;
    ref_angle_ = angle_;
  }
  /// Upper bound of how far any point of the wall moved since setReference().
  double displacementSinceReference() const {
    if (is_static_) return 0.0;
    return (translation_ - ref_translation_).norm() + std::abs(angle_ - ref_angle_) * extent_;
  }

  /// Distance from x to the wall surface (planes: signed, negative behind).
  double distance(const Wall& w, const Vec3& x) const {
    if (w.shape == WallShape::Plane) return (toBody(x) - w.point).dot(unit_normal_);
    return (toBody(x) - closestInBody(w, toBody(x))).norm();
  }

  /// Contact of a ball (centre x, radius r) with the wall; false when apart.
  bool contact(const Wall& w, const Vec3& x, double r, WallContact& out) const {
    const Vec3 xb = toBody(x);
    if (w.shape == WallShape::Plane) {
      // One-sided: a ball behind the plane is still pushed out along its normal.
      const double d = (xb - w.point).dot(unit_normal_);
      if (d >= r) return false;
      out.normal = toWorldDirection(-unit_normal_);
      out.overlap = r - d;
      return true;
    }
    const Vec3 q = closestInBody(w, xb);
    const Vec3 diff = xb - q;
    const double d2 = diff.squaredNorm();
    if (d2 >= r * r) return false;
    const double d = std::sqrt(d2);
    // A centre exactly on the surface has no direction: use the face normal.
    const Vec3 n = d > 0 ? Vec3(-diff / d) : Vec3(-unit_normal_);
    out.normal = toWorldDirection(n);
    out.overlap = r - d;
    return true;
  }

  /// Velocity of the wall material at world point x.
  Vec3 velocityAt(const Vec3& x) const {
    if (is_static_) return Vec3::Zero();
    return velocity_ + omega_.cross(x - centre_);
  }

 private:
  Vec3 toBody(const Vec3& x) const {
    if (is_static_) return x;
    return rotation_.transpose() * (x - centre_) + pivot_;
  }
  Vec3 toWorldDirection(const Vec3& v) const { return is_static_ ? v : Vec3(rotation_ * v); }
  static Vec3 closestInBody(const Wall& w, const Vec3& xb) {
    if (w.shape == WallShape::Polygon) return geometry::closestPointOnConvexPolygon(xb, w.vertices);
    return w.mesh.closestPoint(xb);
  }

  bool is_static_ = true;
  Vec3 unit_normal_ = Vec3::UnitZ();
  double extent_ = 0.0;  // m, farthest vertex from the pivot
  Vec3 translation_ = Vec3::Zero(), velocity_ = Vec3::Zero(), omega_ = Vec3::Zero();
  Vec3 centre_ = Vec3::Zero(), pivot_ = Vec3::Zero();
  double angle_ = 0.0;
  geometry::Mat3 rotation_ = geometry::Mat3::Identity();
  Vec3 ref_translation_ = Vec3::Zero();
  double ref_angle_ = 0.0;
};

}  // namespace rocklab::sim::detail
