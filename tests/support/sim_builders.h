#pragma once
// Builders of small sim worlds shared by the sim and the stability tests. One
// sphere and one plane builder, so that a test reads the same in both suites.
#include <string>

#include "rocklab/sim/model.h"

namespace rocklab::test {

using geometry::Vec3;

/// A sphere at `position`; material 0 is the "ball" of every test model.
inline sim::SphereSpec sphere(const Vec3& position, double radius,
                              const Vec3& velocity = Vec3::Zero(), int material = 0) {
  sim::SphereSpec s;
  s.position = position;
  s.radius = radius;
  s.velocity = velocity;
  s.material = material;
  return s;
}

/// A static plane wall; material 1 is the "wall" of every test model.
inline sim::Wall plane(const std::string& name, const Vec3& point, const Vec3& normal,
                       int material = 1) {
  sim::Wall w;
  w.name = name;
  w.shape = sim::WallShape::Plane;
  w.point = point;
  w.normal = normal.normalized();
  w.material = material;
  return w;
}

/// The horizontal floor z = `z`, facing up.
inline sim::Wall floorPlane(double z = 0.0) {
  return plane("floor", Vec3(0, 0, z), Vec3::UnitZ());
}

}  // namespace rocklab::test
