#pragma once
// The sim tests' contact model; spheres and walls: support/sim_builders.h.
#include "rocklab/sim/world.h"
#include "support/sim_builders.h"

namespace rocklab::test {

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

}  // namespace rocklab::test
