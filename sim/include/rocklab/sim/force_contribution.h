#pragma once
// The seam for forces other than contacts (parallel bonds come next): each
// contribution is called in the `extra forces` stage of World::step, after the
// contact pass and before the kick, in the order the contributions were added,
// and adds into the balls' force and torque accumulators. A world without
// contributions runs the fused contact-and-integration pass and pays nothing.
//
// Bitwise results on any number of threads: the contact pass has finished every
// accumulator before the first contribution runs, and a contribution runs on one
// thread, so each ball receives its sums in one fixed order as long as the
// contribution's own order depends only on the state (e.g. a bond list).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rocklab/sim/particles.h"

namespace rocklab::sim {

/// What a contribution sees: positions at t, velocities and spins at t - dt/2
/// (leapfrog half step, Eq 2-11, 2-12); clump members carry their clump's motion.
struct ForceInput {
  double time = 0.0;  // s
  double dt = 0.0;    // s
  const ParticleState& particles;
};

/// A linear spring-dashpot between two balls, as the contact-network step check
/// (watchdog) sees it: the stiffness the contribution adds must be checked like
/// a contact's, or a stiff bond could make the step unstable unseen.
struct NetworkSpring {
  std::uint32_t a = 0, b = 0;               // ball indices
  Vec3 normal = Vec3::UnitZ();              // unit, from a towards b
  Vec3 point = Vec3::Zero();                // m, where the spring acts
  double kn = 0.0, ks = 0.0;                // N/m, normal and (both) shear directions
  double cn = 0.0, cs = 0.0;                // N s/m, their dashpots
};

class ForceContribution {
 public:
  virtual ~ForceContribution() = default;
  /// For messages and results ("parallel bonds").
  virtual std::string name() const = 0;
  /// Adds this contribution's force (N) and torque (N m) on each ball it acts on.
  virtual void addForces(const ForceInput& in, std::span<Vec3> force, std::span<Vec3> torque) = 0;
  /// Energy it stores (J): counted in Energy::potential_other, so the energy
  /// log and the watchdog's energy check see it.
  virtual double potentialEnergy(const ForceInput& /*in*/) const { return 0.0; }
  /// Its springs for the contact-network step check.
  virtual void networkSprings(const ForceInput& /*in*/, std::vector<NetworkSpring>& /*out*/) const {}
};

}  // namespace rocklab::sim
