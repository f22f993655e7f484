#pragma once
// The sim tests' contact model; spheres and walls: support/sim_builders.h.
#include <cstdint>
#include <functional>
#include <vector>

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

/// What a run of `steps` steps on `threads` threads ended with, to compare runs
/// with bonds breaking: the state hash, the bonds broken in order, the teams used.
struct BreakingRun {
  std::uint64_t hash = 0;
  std::vector<std::uint32_t> broken;
  int threads = 0;
  int bond_threads = 0;
};
inline BreakingRun runWithBreaks(const sim::Model& model, const std::vector<sim::SphereSpec>& spheres,
                                 const std::vector<sim::BondSpec>& bonds, int threads, int steps = 400) {
  sim::World world(model, spheres, {}, bonds, threads);
  world.setTeamPolicy(sim::TeamPolicy::Full);  // the full team throughout: what the tests compare
  for (int s = 0; s < steps; ++s)  // every 50th step observed, as outputs would
    world.step(s % 50 == 0 ? [](const sim::Snapshot&) {} : std::function<void(const sim::Snapshot&)>{});
  BreakingRun r{world.stateHash(), {}, world.threads(), world.bondThreads()};
  for (const sim::BondBreak& e : world.bondBreaks()) r.broken.push_back(e.bond);
  return r;
}

}  // namespace rocklab::test
