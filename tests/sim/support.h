#pragma once
// Small builders shared by the sim tests.
#include "rocklab/sim/world.h"

namespace rocklab::test {

using geometry::Vec3;

/// One material "ball" (index 0) and one "wall" (index 1), linear law, no gravity.
inline sim::Model linearModel(double kn = 1e6, double friction = 0.0, double beta = 0.0) {
  sim::Model m;
  sim::Material ball{"ball", 2730.0, kn, kn, friction, 0.0, 0.2};
  sim::Material wall{"wall", 7800.0, kn, kn, friction, 0.0, 0.2};
  m.materials = {ball, wall};
  m.contact.damping_normal = m.contact.damping_shear = beta;
  m.gravity = Vec3::Zero();
  return m;
}

inline sim::Wall floorPlane(double z = 0.0) {
  sim::Wall w;
  w.name = "floor";
  w.shape = sim::WallShape::Plane;
  w.point = Vec3(0, 0, z);
  w.normal = Vec3::UnitZ();
  w.material = 1;
  return w;
}

inline sim::SphereSpec sphere(Vec3 x, double r, Vec3 v = Vec3::Zero()) {
  sim::SphereSpec s;
  s.position = x;
  s.radius = r;
  s.velocity = v;
  return s;
}

}  // namespace rocklab::test
