#pragma once
// Particle data as structure-of-arrays: one contiguous array per field, so the
// hot loops touch only the fields they need.
//
// The per-ball and per-clump fields are listed once, in the X-macro tables
// below (as MuJoCo's mjxmacro.h does): the structs, World construction,
// removal (withoutBalls), the checkpoint's size check, write and read all
// expand them. Adding a field is one line here plus its meaning where it is set.
#include <cstdint>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim {

using geometry::Quat;
using geometry::Vec3;

/// Rigid clumps (dem-models.md §9): bodies whose member balls are ordinary balls
/// for contacts but move with the body. All arrays are empty when a scene has no
/// clumps, so a sphere-only run pays nothing.
// X(type, name, unit, meaning) for every per-clump array of size c.
#define ROCKLAB_CLUMP_FIELDS(X)                                                                 \
  X(Vec3, position, "m", "centre of mass at t")                                                 \
  X(Vec3, velocity, "m/s", "at t - dt/2 (Eq 2-44 with Eq 2-11)")                                \
  X(Vec3, angular_momentum, "kg m^2/s", "world frame, at t - dt/2 (Eq 2-45)")                   \
  X(Quat, orientation, "", "principal (body) frame -> world, at t")                             \
  X(double, mass, "kg", "")                                                                     \
  X(Vec3, inertia, "kg m^2", "principal moments (body frame)")                                  \
  X(std::uint64_t, id, "", "stable id")

// X(type, name, unit, meaning) for every per-ball array of size n.
#define ROCKLAB_BALL_FIELDS(X)                                                                  \
  X(Vec3, position, "m", "at time t")                                                           \
  X(Vec3, velocity, "m/s", "at t - dt/2 (leapfrog half step, Eq 2-11)")                         \
  X(Vec3, omega, "rad/s", "at t - dt/2 (Eq 2-12)")                                              \
  X(double, radius, "m", "")                                                                    \
  X(double, inv_mass, "1/kg", "")                                                               \
  X(double, inv_inertia, "1/(kg m^2)", "sphere: 1 / (2/5 m R^2) (Eq 2-8); member: its clump's") \
  X(std::int32_t, material, "", "index into Model::materials")                                  \
  X(double, mass, "kg", "member ball: its clump's mass (the dashpots and time step see the body)") \
  X(std::uint64_t, id, "", "stable id (survives removal of other particles)")

#define ROCKLAB_DECLARE_FIELD(type, name, unit, meaning) std::vector<type> name;

/// Rigid clumps (dem-models.md §9): bodies whose member balls are ordinary balls
/// for contacts but move with the body. All arrays are empty when a scene has no
/// clumps, so a sphere-only run pays nothing.
struct ClumpState {
  ROCKLAB_CLUMP_FIELDS(ROCKLAB_DECLARE_FIELD)
  // Members (compressed rows; not in the table: removal renumbers them).
  std::vector<std::uint32_t> member_begin;  // [c+1] first entry of each clump in member_*
  std::vector<std::uint32_t> member_ball;   // [m] ball index of each member
  std::vector<Vec3> member_offset;          // [m] m, member centre in the body frame

  std::size_t size() const { return position.size(); }
};

struct ParticleState {
  ROCKLAB_BALL_FIELDS(ROCKLAB_DECLARE_FIELD)
  // Owning clump of each ball, -1 for a free sphere; empty without clumps (not
  // in the table: it is optional and removal renumbers it).
  std::vector<std::int32_t> clump;
  ClumpState clumps;

  std::size_t size() const { return position.size(); }
};

#undef ROCKLAB_DECLARE_FIELD

}  // namespace rocklab::sim
