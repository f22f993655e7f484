#pragma once
// A wall's pose at the current time and its contact query. Internal.
//
// Geometry is stored in the wall's rest frame (Model::walls); a moving wall maps
// the ball centre into that frame (bodyFromWorld), finds the closest point there
// and maps the result back (worldFromBody). Walls whose surface does not move
// skip both maps; a wall that only spins (model.h WallMotion) has a velocity but
// no pose change.
#include <cmath>
#include <algorithm>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "rocklab/geometry/closest_point.h"
#include "rocklab/geometry/triangle_mesh_index.h"
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
    is_static_ = !w.motion.surfaceMoves();
    moves_material_ = !w.motion.isStatic();
    if (w.shape == WallShape::Plane) {
      unit_normal_ = w.normal.normalized();
    } else if (w.shape == WallShape::Polygon) {
      unit_normal_ = polygonNormal(w.vertices);
      for (const Vec3& v : w.vertices) extent_ = std::max(extent_, (v - w.motion.pivot).norm());
    } else {
      unit_normal_ = Vec3::UnitZ();
      for (const Vec3& v : w.mesh.vertices) extent_ = std::max(extent_, (v - w.motion.pivot).norm());
      mesh_index_ =
          geometry::TriangleMeshIndex(w.mesh, w.smooth_angle_deg * std::numbers::pi / 180.0);
    }
  }

  /// Pose and activity at time t.
  void update(const Wall& w, double t) {
    active = w.activeAt(t);
    if (!moves_material_) return;
    pose_ = wallPoseAt(w.motion, t);
    centre_ = pose_.pivot + pose_.translation;
  }

  void setReference() {
    ref_translation_ = pose_.translation;
    ref_angle_ = pose_.angle;
  }
  /// Upper bound of how far any point of the wall moved since setReference().
  double displacementSinceReference() const {
    if (is_static_) return 0.0;
    return (pose_.translation - ref_translation_).norm() + std::abs(pose_.angle - ref_angle_) * extent_;
  }

  /// Distance from x to the wall surface (planes: signed, negative behind).
  double distance(const Wall& w, const Vec3& x) const {
    if (w.shape == WallShape::Plane) return (toBody(x) - w.point).dot(unit_normal_);
    return (toBody(x) - closestInBody(w, toBody(x))).norm();
  }

  /// Whether x is nearer than `range` to the wall (planes: signed distance, so a
  /// point behind is near). A mesh wall also appends the triangles nearer than
  /// `range` (nearest first) to `triangles` and their distances to `distances`: a
  /// ball's candidates until the next neighbour build (meshTouches()).
  bool near(const Wall& w, const Vec3& x, double range, std::vector<std::uint32_t>& triangles,
            std::vector<double>& distances) const {
    if (w.shape != WallShape::Mesh) return distance(w, x) < range;
    const std::size_t before = triangles.size();
    mesh_index_.trianglesWithin(toBody(x), range, triangles, &distances);
    return triangles.size() > before;
  }

  /// Contact of a ball (centre x, radius r) with a plane or polygon wall; false
  /// when apart. A mesh wall's contacts are meshTouches().
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
    const Vec3 diff = xb - closestInBody(w, xb);
    const double d2 = diff.squaredNorm();
    if (d2 >= r * r) return false;
    const double d = std::sqrt(d2);
    // A centre exactly on the surface has no direction: use the face normal.
    const Vec3 n = d > 0 ? Vec3(-diff / d) : Vec3(-unit_normal_);
    out.normal = toWorldDirection(n);
    out.overlap = r - d;
    return true;
  }

  /// A mesh wall's touches of a ball (centre x, radius r), nearest first, at most
  /// out.size() of them; returns how many. Only `triangles` are looked at, the
  /// ball's candidates of the last neighbour build (near() with r + skin): the
  /// same touches as a search of the whole mesh while the ball and the wall have
  /// moved less than the skin (TriangleMeshIndex::touchesAmong). With `distances`
  /// (near()'s) and how far the ball has moved since (`ball_moved`, m) the
  /// triangles that cannot come within r are not tested.
  std::size_t meshTouches(const Vec3& x, double r, std::span<const std::uint32_t> triangles,
                          std::span<WallContact> out, std::span<const double> distances = {},
                          double ball_moved = 0) const {
    thread_local std::vector<geometry::TriangleMeshIndex::Touch> found;
    const Vec3 xb = toBody(x);
    mesh_index_.touchesAmong(xb, r, triangles, found, {distances, ball_moved + displacementSinceReference()});
    const std::size_t n = std::min(found.size(), out.size());
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 diff = xb - found[k].point;
      const double d = found[k].distance;
      // A centre exactly on the surface has no direction: use the face normal.
      const Vec3 normal = d > 0 ? Vec3(-diff / d) : Vec3(-unit_normal_);
      out[k] = {toWorldDirection(normal), r - d};
    }
    return n;
  }

  /// Velocity of the wall material at world point x.
  Vec3 velocityAt(const Vec3& x) const {
    if (!moves_material_) return Vec3::Zero();
    return pose_.velocityAt(x);
  }
  /// Velocity of the wall material at a contact at x with unit normal n: the
  /// spin's normal part removed (WallPose::contactVelocityAt says why).
  Vec3 contactVelocityAt(const Vec3& x, const Vec3& n) const {
    if (!moves_material_) return Vec3::Zero();
    return pose_.contactVelocityAt(x, n);
  }

 private:
  Vec3 toBody(const Vec3& x) const {
    if (is_static_) return x;
    return pose_.rotation.transpose() * (x - centre_) + pose_.pivot;
  }
  Vec3 toWorldDirection(const Vec3& v) const { return is_static_ ? v : Vec3(pose_.rotation * v); }
  Vec3 closestInBody(const Wall& w, const Vec3& xb) const {
    if (w.shape == WallShape::Polygon) return geometry::closestPointOnConvexPolygon(xb, w.vertices);
    return mesh_index_.closestPoint(xb);
  }

  bool is_static_ = true;        // the surface never moves: no pose maps
  bool moves_material_ = false;  // a velocity (the surface's motion or a spin)
  Vec3 unit_normal_ = Vec3::UnitZ();
  double extent_ = 0.0;  // m, farthest vertex from the pivot
  geometry::TriangleMeshIndex mesh_index_;  // mesh walls: closest points through an AABB tree
  WallPose pose_;                 // at the current time (moving walls only)
  Vec3 centre_ = Vec3::Zero();    // pivot + translation
  Vec3 ref_translation_ = Vec3::Zero();
  double ref_angle_ = 0.0;
};

}  // namespace rocklab::sim::detail
