#include "../world_impl.h"

namespace rocklab::sim {

// Stage 5, extra forces: the force contributions (force_contribution.h) add
// into the accumulators after the contact pass has finished every ball, one
// contribution after the other in the order they were added, on this thread:
// each ball's sums keep one order on any number of threads.
// Reads: positions at t, velocities and spins at t - dt/2 (ForceInput).
// Writes: scratch.acc_force/acc_torque (adds); the contributions' own state.

void World::Impl::extraForceStage() {
  const ForceInput in = forceInput();
  for (const auto& contribution : contributions)
    contribution->addForces(in, scratch.acc_force, scratch.acc_torque);
}

}  // namespace rocklab::sim
