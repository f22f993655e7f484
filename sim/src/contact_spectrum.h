#pragma once
// The stability of the step for the whole contact network, for the watchdog.
// Internal to rocklab_sim.
//
// Why: the automatic step is per contact (sqrt(m/k) of the stiffest single
// partner, capped by the damped limit of one contact), but a body pressed by
// many contacts, and a stuck shear spring that turns the body as well as
// pushing it (inverse mass 1/m + R^2/I), vibrate faster, and their dashpots add
// up. Reference §7a sums a body's contact stiffnesses for that reason. A pile
// past the limit does not blow up: its unstable modes grow until the contacts
// slip, and it creeps with its energy falling, which neither the energy nor the
// overlap check can see (docs/stability.md).
//
// The leapfrog with the dashpot on the half-step velocity (stages 3 and 8 of
// world.h) maps a mode x onto -x after one step exactly when
//   (K + 2 C / dt) x = (4 / dt^2) M x,
// (put x' = -x, v' = -v into v' = v - dt M^-1 (K x + C v), x' = x + dt v'), so
// the step is stable while the largest eigenvalue L of M^-1 (K + 2 C / dt) stays
// below 4 / dt^2; for one undamped mode that is omega dt < 2, for one damped mode
// the limit of dampedStabilityLimit(). K and C are the springs and dashpots of
// every touching contact (normal, and both shear directions while the contact
// sticks) acting on the bodies' translations and rotations.
//
// L is estimated by power iteration (matrix-free, one pass over the contacts per
// iteration), warm-started from the previous estimate's vector, so a few
// iterations per check converge while the network changes slowly. Power
// iteration approaches L from below: an estimate above the limit is a mode that
// really is unstable (no false alarm).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim::detail {

using geometry::Mat3;
using geometry::Vec3;

/// A rigid body of the network (a free ball or a clump). A free ball's inertia
/// is a scalar, so only a clump carries matrices (issue 22's memory budget).
struct NetworkBody {
  double inv_mass = 0.0;     // 1/kg
  double inv_inertia = 0.0;  // 1/(kg m^2) of a free ball (isotropic); unused for a clump
  std::int32_t source = 0;   // the ball's index in the state, or the clump's
  std::int32_t clump = -1;   // index into ContactNetwork::clump_*; -1: a free ball
};

/// One touching contact between bodies a and b (b < 0: a wall, immovable).
struct NetworkContact {
  std::int32_t a = 0, b = -1;
  Vec3 normal = Vec3::UnitZ();  // unit
  Vec3 lever_a = Vec3::Zero();  // m, contact point minus a's centre of mass
  Vec3 lever_b = Vec3::Zero();  // m, the same for b
  double kn = 0.0;              // N/m, tangent normal stiffness
  double ks = 0.0;              // N/m, shear stiffness (0 while sliding)
  double cn = 0.0;              // N s/m, normal dashpot
  double cs = 0.0;              // N s/m, shear dashpot (0 while sliding)
};

/// The contacts are not stored: a source hands every touching contact to the
/// visitor, in the same order at every call, and the power iteration asks for
/// them once per iteration. A stored list was the largest array of the run on
/// contact-rich scenes (112 bytes a contact, 4-6 contacts a ball) for a check
/// that runs two iterations every 1,000 steps.
using ContactVisitor = std::function<void(const NetworkContact&)>;
using ContactSource = std::function<void(const ContactVisitor&)>;

struct ContactNetwork {
  std::vector<NetworkBody> bodies;
  std::vector<Mat3> clump_inertia;      // kg m^2, world frame, per clump
  std::vector<Mat3> clump_inv_inertia;  // 1/(kg m^2)
};

/// Power-iteration state kept between checks: 6 entries per body (translation,
/// rotation), M-normalised.
struct SpectrumEstimate {
  std::vector<double> vector;
  double eigenvalue = 0.0;    // 1/s^2, Rayleigh quotient of M^-1 (K + w C) for `vector`
  double stiffness = 0.0;     // 1/s^2, its K part (omega^2 of the mode)
  double damping = 0.0;       // 1/s, its C part
  std::int32_t body = -1;     // body with the largest share of the mode's energy
  std::size_t contacts = 0;   // touching contacts at the last call
  std::uint64_t calls = 0;    // iterateSpectrum calls so far (picks each call's fresh vector)
};

/// Runs `iterations` power iterations on M^-1 (K + damping_weight C) from
/// `estimate.vector` plus 1 % of a fresh pseudo-random vector (the same sequence
/// on every run and thread count; the random vector alone when the size does
/// not match) and updates the estimate. The step check uses damping_weight = 2 / dt.
void iterateSpectrum(const ContactNetwork& network, const ContactSource& contacts, double damping_weight,
                     int iterations, SpectrumEstimate& estimate);

/// The largest step at which a mode of stiffness quotient `stiffness` (1/s^2)
/// and damping quotient `damping` (1/s) is stable: the root of
/// stiffness + 2 damping / dt = 4 / dt^2.
double stableStep(double stiffness, double damping);

}  // namespace rocklab::sim::detail
