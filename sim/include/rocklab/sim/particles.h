#pragma once
// Particle data as structure-of-arrays: one contiguous array per field, so the
// hot loops touch only the fields they need. Hot fields (integrated every step)
// come first; cold fields (set once) after.
#include <cstdint>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim {

using geometry::Quat;
using geometry::Vec3;

/// Rigid clumps (dem-models.md §9): bodies whose member balls are ordinary balls
/// for contacts but move with the body. All arrays are empty when a scene has no
/// clumps, so a sphere-only run pays nothing.
struct ClumpState {
  // --- hot
  std::vector<Vec3> position;          // [c] m        centre of mass at t
  std::vector<Vec3> velocity;          // [c] m/s      at t - dt/2 (Eq 2-44 with Eq 2-11)
  std::vector<Vec3> angular_momentum;  // [c] kg m^2/s world frame, at t - dt/2 (Eq 2-45)
  std::vector<Quat> orientation;       // [c]          principal (body) frame -> world, at t
  // --- cold
  std::vector<double> mass;            // [c] kg
  std::vector<Vec3> inertia;           // [c] kg m^2   principal moments (body frame)
  std::vector<std::uint32_t> member_begin;  // [c+1] first entry of each clump in member_*
  std::vector<std::uint32_t> member_ball;   // [m] ball index of each member
  std::vector<Vec3> member_offset;          // [m] m, member centre in the body frame
  std::vector<std::uint64_t> id;            // [c] stable id

  std::size_t size() const { return position.size(); }
};

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
  // --- clumps (empty without clumps). A member ball carries its clump's mass and
  // smallest principal inertia (used by the time-step audit and the dashpots).
  std::vector<std::int32_t> clump;  // [n] owning clump, -1 for a free sphere
  ClumpState clumps;

  std::size_t size() const { return position.size(); }
};

}  // namespace rocklab::sim
