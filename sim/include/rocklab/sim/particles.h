#pragma once
// Particle data as structure-of-arrays: one contiguous array per field, so the
// hot loops touch only the fields they need. Hot fields (integrated every step)
// come first; cold fields (set once) after.
#include <cstdint>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim {

using geometry::Vec3;

struct ParticleState {
  // --- hot: read or written every step
  std::vector<Vec3> position;    // [n] m       at time t
  std::vector<Vec3> velocity;    // [n] m/s     at t - dt/2 (leapfrog half step, Eq 2-11)
  std::vector<Vec3> omega;       // [n] rad/s   at t - dt/2 (Eq 2-12)
  std::vector<double> radius;    // [n] m
  std::vector<double> inv_mass;  // [n] 1/kg
  std::vector<double> inv_inertia;  // [n] 1/(kg m^2), sphere: 1 / (2/5 m R^2) (Eq 2-8)
  std::vector<std::int32_t> material;  // [n] index into Model::materials
  // --- cold
  std::vector<double> mass;      // [n] kg
  std::vector<std::uint64_t> id;  // [n] stable id (survives removal of other particles)

  std::size_t size() const { return position.size(); }
};

}  // namespace rocklab::sim
