#include "../rigid_body.h"
#include "../world_impl.h"

namespace rocklab::sim {

// Stage 6, observe (only on steps an observer, the energy check or the network
// check asked for): the whole-step state before the kick.
// Reads: velocities and spins at t - dt/2, scratch.acc_force/acc_torque, clumps.
// Writes: obs (velocities synchronised to t, v(t) = v(t - dt/2) + a(t) dt/2,
// clump loads and motion, the energy).

void World::Impl::observeStage() {
  const std::size_t n = p.size();
  obs.velocity.resize(n);
  obs.omega.resize(n);
  // At the first step v holds v(0) already.
  const double half = half_kick_pending ? 0.0 : 0.5 * dt;
  for (std::size_t i = 0; i < n; ++i) {
    obs.velocity[i] = p.velocity[i] + half * (scratch.acc_force[i] * p.inv_mass[i] + gravity);
    obs.omega[i] = p.omega[i] + half * p.inv_inertia[i] * scratch.acc_torque[i];
  }
  const ClumpState& k = p.clumps;
  obs.clump_velocity.resize(k.size());
  obs.clump_omega.resize(k.size());
  obs.clump_force.resize(k.size());
  for (std::size_t c = 0; c < k.size(); ++c) {
    Vec3 torque;
    clumpLoad(c, obs.clump_force[c], torque);
    obs.clump_force[c] += gravity * k.mass[c];
    obs.clump_velocity[c] = k.velocity[c] + (half / k.mass[c]) * obs.clump_force[c];
    obs.clump_omega[c] =
        detail::angularVelocity(k.orientation[c], k.inertia[c], k.angular_momentum[c] + half * torque);
    for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
      const std::uint32_t i = k.member_ball[m];
      obs.velocity[i] = obs.clump_velocity[c] + obs.clump_omega[c].cross(p.position[i] - k.position[c]);
      obs.omega[i] = obs.clump_omega[c];
    }
  }
  obs.energy = energyAny(obs.velocity, obs.omega);
}

/// The observer's view of stage 6's results; the two buffers hold what the
/// snapshot's spans point at and must outlive the observer call.
Snapshot World::Impl::snapshot(std::vector<Vec3>& total_force, std::vector<std::uint8_t>& wall_active) const {
  const std::size_t n = p.size();
  const ClumpState& k = p.clumps;
  total_force.resize(n);  // total force including gravity
  for (std::size_t i = 0; i < n; ++i)
    total_force[i] = scratch.acc_force[i] + gravity * (isMember(i) ? 0.0 : p.mass[i]);
  wall_active.resize(walls.size());
  for (std::size_t w = 0; w < walls.size(); ++w) wall_active[w] = walls[w].active ? 1 : 0;
  Snapshot s;
  s.time = time;
  s.step = step;
  s.energy = obs.energy;
  s.position = p.position;
  s.velocity = obs.velocity;
  s.omega = obs.omega;
  s.force = total_force;
  s.radius = p.radius;
  s.id = p.id;
  s.material = p.material;
  s.wall_active = wall_active;
  s.clump = p.clump;
  s.clump_position = k.position;
  s.clump_velocity = obs.clump_velocity;
  s.clump_omega = obs.clump_omega;
  s.clump_orientation = k.orientation;
  s.clump_force = obs.clump_force;
  s.clump_id = k.id;
  s.bond_intact = bonds.state.intact;  // all three empty without bonds
  s.bond_a = bonds.state.a;
  s.bond_b = bonds.state.b;
  for (std::uint8_t t : history.pair_touch) s.contacts += t;
  for (std::uint8_t t : history.wall_touch) s.wall_contacts += t;
  return s;
}

}  // namespace rocklab::sim
