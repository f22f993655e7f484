#pragma once
// Cone-crusher mantle motion (experiments.md §g.3, Eq 6-9): an eccentric
// gyration at omega_ecc about the crusher's vertical axis (rocklab z through the
// origin), which carries the tilted mantle around, composed with a spin at
// omega_spin about the mantle's own axis:
//
//   x(t) = G(t) [ p0 + S(t) (x0 - p0) ]            (x0: a mantle point at t = 0)
//   G(t) = rotation by omega_ecc t about z,  S(t) = rotation by sigma omega_spin t about a0 through p0
//   v(x) = omega_ecc (e_z x x) + sigma omega_spin (a x (x - x_a)),  a = G a0, x_a = G p0
//
// sigma = -1 (spin opposite to the gyration, the default) is the reference's
// v = omega_ecc (e_v x x) - omega_spin (a x (x - x_a)). Eq 6-9: omega_spin =
// (R_bot_m + e)/R_bot_m omega_ecc, e the bottom centre's offset from the axis (s
// as printed): the closed-side bottom edge (e + R from the axis, R from the mantle
// axis) then rolls without sliding; the net rotation about the mantle axis is
// omega_ecc - omega_spin = -(e/R) omega_ecc (retrograde, ~ -9 rpm at 300 rpm).
//
// The pose is computed from t alone (angles reduced to one turn from t x
// revolutions per second), never by accumulating steps: no drift after any number
// of revolutions.
#include "rocklab/geometry/vec.h"

namespace rocklab::geometry {

struct ConeCrusherGeometry;

enum class SpinSense { Opposite, Same, None };

struct MantleMotion {
  double eccentric_speed = 0;  // rad/s  omega_ecc, counter-clockwise about +z seen from above
  double spin_speed = 0;       // rad/s  omega_spin >= 0, magnitude (Eq 6-9)
  SpinSense spin_sense = SpinSense::Opposite;
  Vec3 axis = Vec3::UnitZ();   // unit mantle axis at t = 0
  Vec3 axis_point = Vec3::Zero();  // m, a point of the mantle axis at t = 0 (O_bot_m)

  double signedSpin() const;   // rad/s  sigma omega_spin
};

/// The crusher's motion: omega_ecc from rpm, omega_spin by Eq 6-9, axis and point from the mantle.
MantleMotion mantleMotion(const ConeCrusherGeometry& g, double eccentric_rpm, SpinSense sense);

/// A rigid placement x = rotation x0 + translation.
struct RigidPose {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
  Vec3 place(const Vec3& x0) const { return rotation * x0 + translation; }
};

RigidPose mantlePoseAt(const MantleMotion& m, double t);
/// Velocity of the mantle material at world point x at time t (the field above).
Vec3 mantleVelocityAt(const MantleMotion& m, double t, const Vec3& x);
/// Angular velocity of the mantle at t: omega_ecc e_z + sigma omega_spin a(t).
Vec3 mantleAngularVelocityAt(const MantleMotion& m, double t);
/// An angle omega t reduced to [0, 2 pi) through the turns omega t / (2 pi), so
/// whole turns give 0 to round-off whatever t.
double turnAngle(double omega, double t);

const char* toString(SpinSense s);  // "opposite" | "same" | "none"

}  // namespace rocklab::geometry
