#pragma once
// What observers (output writers, energy log, watchdog) see at a whole step t:
// positions at t and velocities synchronised to t (v(t) = v(t - dt/2) + a(t) dt/2,
// the velocity-Verlet value), with the total force and torque at t. Member
// balls of a clump carry the clump's motion; their `force` is the contact force
// on that member alone (gravity acts on the clump, see clump_force).
#include <cstdint>
#include <span>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim {

struct Energy {
  double kinetic_translational = 0.0;  // J
  double kinetic_rotational = 0.0;     // J
  double potential_gravity = 0.0;      // J, -sum m g.x (datum at the origin)
  double elastic = 0.0;                // J, stored in normal and shear contact springs
  double bond = 0.0;                   // J, stored in intact parallel bonds (bonds.h)
  double potential_other = 0.0;        // J, stored by force contributions (force_contribution.h)
  double total() const {
    return kinetic_translational + kinetic_rotational + potential_gravity + elastic + bond + potential_other;
  }
};

struct Snapshot {
  double time = 0.0;         // s
  std::uint64_t step = 0;    // steps since t = 0
  std::span<const geometry::Vec3> position;  // [n] m
  std::span<const geometry::Vec3> velocity;  // [n] m/s, synchronised to `time`
  std::span<const geometry::Vec3> omega;     // [n] rad/s, synchronised to `time`
  std::span<const geometry::Vec3> force;     // [n] N, total including gravity
  std::span<const double> radius;            // [n] m
  std::span<const std::uint64_t> id;         // [n]
  std::span<const std::int32_t> material;    // [n] index into Model::materials
  std::span<const std::uint8_t> wall_active; // [walls] 1 when the wall exists at `time`
  // Rigid clumps (all empty without clumps). Member balls appear above too.
  std::span<const std::int32_t> clump;                 // [n] owning clump or -1
  std::span<const geometry::Vec3> clump_position;      // [c] m, centre of mass
  std::span<const geometry::Vec3> clump_velocity;      // [c] m/s, synchronised to `time`
  std::span<const geometry::Vec3> clump_omega;         // [c] rad/s, synchronised to `time`
  std::span<const geometry::Quat> clump_orientation;   // [c] body -> world
  std::span<const geometry::Vec3> clump_force;         // [c] N, total including gravity
  std::span<const std::uint64_t> clump_id;             // [c]
  Energy energy;
  std::size_t contacts = 0;       // touching ball–ball pairs
  std::size_t wall_contacts = 0;  // touching ball–wall pairs
};

}  // namespace rocklab::sim
