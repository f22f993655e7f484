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

/// What a Snapshot array is indexed by: balls [n] (clump members included),
/// clumps [c], walls or parallel bonds [bonds] (WorldState::bonds, intact and broken).
enum class SnapshotIndex { Ball, Clump, Wall, Bond };
/// Whether a run.h5 frame (output/run_file.cpp) writes a Snapshot array: Always,
/// IfAny (when not empty), WithClumps (when the snapshot has clumps), Never, or
/// PerFile: once per file in /bonds (Bond arrays that change only when balls are
/// removed and renumbered; a frame whose values differ carries its own copy).
enum class FrameWrite { Always, IfAny, WithClumps, Never, PerFile };

// The Snapshot's arrays, listed once: the struct, the run.h5 frame writer and
// reader, and the size check (output/snapshot_check.h) expand this table.
// X(type, name, index, unit, frame, meaning); index is a SnapshotIndex, frame a
// FrameWrite. Clump arrays are all empty without clumps, bond arrays without
// bonds (so such frames hold no bond datasets); member balls appear in the ball
// arrays too. Where each gets its value: World::Impl::snapshot
// (sim/src/stages/observe.cpp).
#define ROCKLAB_SNAPSHOT_FIELDS(X)                                                      \
  X(geometry::Vec3, position, Ball, "m", Always, "at `time`")                           \
  X(geometry::Vec3, velocity, Ball, "m/s", Always, "synchronised to `time`")            \
  X(geometry::Vec3, omega, Ball, "rad/s", Always, "synchronised to `time`")             \
  X(geometry::Vec3, force, Ball, "N", Always, "total including gravity")                \
  X(double, radius, Ball, "m", Always, "")                                              \
  X(std::uint64_t, id, Ball, "", Always, "stable id")                                   \
  X(std::int32_t, material, Ball, "", IfAny, "index into Model::materials")             \
  X(std::uint8_t, wall_active, Wall, "", IfAny, "1 when the wall exists at `time`")     \
  X(std::int32_t, clump, Ball, "", WithClumps, "owning clump or -1")                    \
  X(geometry::Vec3, clump_position, Clump, "m", WithClumps, "centre of mass")           \
  X(geometry::Vec3, clump_velocity, Clump, "m/s", WithClumps, "synchronised to `time`") \
  X(geometry::Vec3, clump_omega, Clump, "rad/s", WithClumps, "synchronised to `time`")  \
  X(geometry::Quat, clump_orientation, Clump, "", WithClumps, "body -> world")          \
  X(geometry::Vec3, clump_force, Clump, "N", Never, "total including gravity")          \
  X(std::uint64_t, clump_id, Clump, "", WithClumps, "stable id")                        \
  X(std::uint8_t, bond_intact, Bond, "", IfAny, "1 while bond k holds, then 0 for ever")  \
  X(std::uint32_t, bond_a, Bond, "", PerFile, "first ball of bond k (index)")             \
  X(std::uint32_t, bond_b, Bond, "", PerFile, "second ball of bond k (index)")

#define ROCKLAB_SNAPSHOT_SPAN(type, name, index, unit, frame, meaning) std::span<const type> name;

struct Snapshot {
  double time = 0.0;         // s
  std::uint64_t step = 0;    // steps since t = 0
  ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_SNAPSHOT_SPAN)
  Energy energy;
  std::size_t contacts = 0;       // touching ball–ball pairs
  std::size_t wall_contacts = 0;  // touching ball–wall contacts (a ball in a mesh's crease touches it twice)
};

#undef ROCKLAB_SNAPSHOT_SPAN

}  // namespace rocklab::sim
