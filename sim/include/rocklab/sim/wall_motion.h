#pragma once
// Prescribed wall motion (model.h WallMotion) evaluated at a time: the one
// formula that the engine (src/wall_runtime.h) and the frame builder (what the
// cameras draw) share, so a drawn wall is where the balls feel it.
//
//   x(t) = pivot + T(t) + R(t) (x0 - pivot),   T(t) = v t + A sin(2 pi f t),
//   R(t) = rotation by |omega| t about omega  (x0: a point of the wall at rest)
//
// R(t) is built from the angle reduced to one turn (geometry::turnAngle), so the
// pose after any number of whole turns is the pose at t = 0 to round-off. A spin
// (WallMotion::spin_rate) adds to the velocity only (model.h says why).
#include <cmath>
#include <algorithm>
#include <numbers>
#include <string>
#include <vector>

#include "rocklab/geometry/mantle_motion.h"  // turnAngle
#include "rocklab/sim/model.h"

namespace rocklab::sim {

struct WallPose {
  geometry::Vec3 translation = geometry::Vec3::Zero();  // m, T(t)
  geometry::Vec3 velocity = geometry::Vec3::Zero();     // m/s, dT/dt
  geometry::Vec3 omega = geometry::Vec3::Zero();        // rad/s
  geometry::Vec3 pivot = geometry::Vec3::Zero();        // m, at rest
  double angle = 0.0;                                   // rad turned since t = 0 (not reduced)
  geometry::Mat3 rotation = geometry::Mat3::Identity(); // R(t)
  double spin_rate = 0.0;                               // rad/s, about spin_axis
  geometry::Vec3 spin_axis = geometry::Vec3::UnitZ();   // unit, world frame at t: R a0
  geometry::Vec3 spin_point = geometry::Vec3::Zero();   // m, world frame at t: x_a

  /// Where the rest point x0 of the wall is at this pose.
  geometry::Vec3 place(const geometry::Vec3& x0) const { return pivot + translation + rotation * (x0 - pivot); }
  /// Velocity of the wall material at world point x (the spin included).
  geometry::Vec3 velocityAt(const geometry::Vec3& x) const { return surfaceVelocityAt(x) + spinVelocityAt(x); }
  /// Velocity of the moving surface (translation and rotation) at world point x.
  geometry::Vec3 surfaceVelocityAt(const geometry::Vec3& x) const {
    return velocity + omega.cross(x - (pivot + translation));
  }
  /// Velocity the spin alone gives the material at world point x.
  geometry::Vec3 spinVelocityAt(const geometry::Vec3& x) const {
    if (spin_rate == 0.0) return geometry::Vec3::Zero();
    return spin_rate * spin_axis.cross(x - spin_point);
  }
  /// Velocity of the wall material at a contact at x with unit normal n (either
  /// sense): the surface's motion in full, the spin's tangential part only. The
  /// spin maps the true surface (a surface of revolution) onto itself, so its
  /// velocity there is tangential; on the faceted mesh that stands for it, omega x r
  /// has a normal part (up to |omega| R sin(pi / segments) at a facet's edge) that
  /// the overlap never sees, as the pose does not spin. Left in, it drives the
  /// normal dashpot and enters the wall work F . v: on a ball pinched between the
  /// mantle and the concave the spurious power F_n v_n grows with the pinch force
  /// (docs/crusher.md: the PBM run's energy watchdog).
  geometry::Vec3 contactVelocityAt(const geometry::Vec3& x, const geometry::Vec3& n) const {
    const geometry::Vec3 spin = spinVelocityAt(x);
    return surfaceVelocityAt(x) + (spin - spin.dot(n) * n);
  }
};

inline WallPose wallPoseAt(const WallMotion& m, double t) {
  WallPose p;
  const double phase = 2.0 * std::numbers::pi * m.frequency;
  p.translation = m.velocity * t + m.amplitude * std::sin(phase * t);
  p.velocity = m.velocity + m.amplitude * (phase * std::cos(phase * t));
  p.omega = m.angular_velocity;
  p.pivot = m.pivot;
  p.angle = p.omega.norm() * t;
  const double turned = geometry::turnAngle(p.omega.norm(), t);
  p.rotation = turned > 0 ? geometry::Mat3(Eigen::AngleAxisd(turned, p.omega.normalized()).toRotationMatrix())
                          : geometry::Mat3::Identity();
  p.spin_rate = m.spin_rate;
  if (p.spin_rate != 0.0) p.spin_axis = p.rotation * m.spin_axis.normalized();
  p.spin_point = p.place(m.spin_point);
  return p;
}

/// Unit normal of a planar polygon, right-handed over its first three vertices
/// (zero when they are collinear; validateModel refuses such a wall).
inline geometry::Vec3 polygonNormal(const std::vector<geometry::Vec3>& v) {
  return (v[1] - v[0]).cross(v[2] - v[0]).normalized();
}

/// "" or why `v` is no polygon wall: fewer than 3 vertices, the first three
/// collinear, or a vertex off their plane. One rule for validateModel and the
/// scene reader (which can name the key and its line).
inline std::string polygonProblem(const std::vector<geometry::Vec3>& v) {
  if (v.size() < 3) return "a polygon needs at least 3 vertices";
  const geometry::Vec3 normal = polygonNormal(v);
  if (!(normal.norm() > 0)) return "the first three vertices are collinear (or repeated): they span no plane";
  const double scale = (v[1] - v[0]).norm();
  for (std::size_t k = 3; k < v.size(); ++k)
    if (!(std::abs((v[k] - v[0]).dot(normal)) <= 1e-9 * std::max(1.0, scale)))
      return "vertex " + std::to_string(k) + " is not in the plane of the first three";
  return {};
}

}  // namespace rocklab::sim
