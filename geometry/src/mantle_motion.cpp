#include "rocklab/geometry/mantle_motion.h"

#include <cmath>
#include <numbers>

#include "rocklab/geometry/cone_crusher.h"

namespace rocklab::geometry {

namespace {

Mat3 rotationAbout(const Vec3& unit_axis, double angle) {
  return Eigen::AngleAxisd(angle, unit_axis).toRotationMatrix();
}

}  // namespace

const char* toString(SpinSense s) {
  switch (s) {
    case SpinSense::Opposite: return "opposite";
    case SpinSense::Same: return "same";
    case SpinSense::None: return "none";
  }
  return "?";
}

double MantleMotion::signedSpin() const {
  switch (spin_sense) {
    case SpinSense::Opposite: return -spin_speed;
    case SpinSense::Same: return spin_speed;
    case SpinSense::None: return 0.0;
  }
  return 0.0;
}

double turnAngle(double omega, double t) {
  const double turns = omega * t / (2 * std::numbers::pi);
  return 2 * std::numbers::pi * (turns - std::floor(turns));
}

MantleMotion mantleMotion(const ConeCrusherGeometry& g, double eccentric_rpm, SpinSense sense) {
  MantleMotion m;
  m.eccentric_speed = eccentric_rpm * 2 * std::numbers::pi / 60.0;
  m.spin_speed = (g.R_bot_m + g.bottom_offset) / g.R_bot_m * std::abs(m.eccentric_speed);  // Eq 6-9
  m.spin_sense = sense;
  m.axis = g.mantle_axis;
  m.axis_point = g.O_bot_m.world();
  return m;
}

RigidPose mantlePoseAt(const MantleMotion& m, double t) {
  const Mat3 G = rotationAbout(Vec3::UnitZ(), turnAngle(m.eccentric_speed, t));
  const Mat3 S = rotationAbout(m.axis, turnAngle(m.signedSpin(), t));
  RigidPose p;
  p.rotation = G * S;
  p.translation = G * (m.axis_point - S * m.axis_point);
  return p;
}

Vec3 mantleAngularVelocityAt(const MantleMotion& m, double t) {
  const Mat3 G = rotationAbout(Vec3::UnitZ(), turnAngle(m.eccentric_speed, t));
  return m.eccentric_speed * Vec3::UnitZ() + m.signedSpin() * (G * m.axis);
}

Vec3 mantleVelocityAt(const MantleMotion& m, double t, const Vec3& x) {
  const Mat3 G = rotationAbout(Vec3::UnitZ(), turnAngle(m.eccentric_speed, t));
  const Vec3 a = G * m.axis, x_a = G * m.axis_point;
  return m.eccentric_speed * Vec3::UnitZ().cross(x) + m.signedSpin() * a.cross(x - x_a);
}

}  // namespace rocklab::geometry
