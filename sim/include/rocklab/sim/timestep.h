#pragma once
// Critical time steps (ref. dem-models.md §7a, [X]) and the start-up audit.
#include <string>

#include "rocklab/sim/bonds.h"
#include "rocklab/sim/model.h"
#include "rocklab/sim/particles.h"

namespace rocklab::sim {

/// Spring criterion for one body: min(sqrt(m / k_n), sqrt(I / (k_s R^2))).
double springCriticalStep(double mass, double inertia, double radius, double kn, double ks);

/// Rayleigh-wave step: pi R sqrt(rho / G) / (0.1631 nu + 0.8766).
double rayleighStep(double radius, double density, double shear_modulus, double poisson);

/// Normal force coefficient c of F = c delta^(3/2) for the study's Hertz law (Eq 2-22).
double hertzCoefficient(double shear_modulus, double poisson, double r_tilde);

/// Largest overlap of an undamped Hertz impact: (5 m v^2 / (4 c))^(2/5).
double hertzMaxOverlap(double mass, double c, double velocity);

/// Duration of an undamped Hertz impact: 2.9432 delta_max / v.
double hertzContactTime(double mass, double c, double velocity);

/// Duration of a linear spring–dashpot contact: pi / (omega0 sqrt(1 - beta^2)).
double linearContactTime(double mass, double k, double beta);

/// Exact stability limit of the leapfrog for one contact mode with a dashpot:
/// relative coordinate x with inverse mass `inv_mass`, spring k and dashpot c
/// acting on the half-step velocity (what the engine does). The update
/// v' = v - dt inv_mass (k x + c v), x' = x + dt v' is stable iff
/// (w dt)^2 + 2 c inv_mass dt < 4 (w^2 = k inv_mass), i.e.
/// dt < 4 / (c inv_mass + sqrt((c inv_mass)^2 + 4 k inv_mass)); 2 / w when c = 0.
double dampedStabilityLimit(double k, double c, double inv_mass);

/// Restitution of a linear spring–dashpot contact, Eq 4-4: exp(-beta pi / sqrt(1 - beta^2)).
double restitutionFromDamping(double beta);
/// Inverse of Eq 4-4: beta = -ln e / sqrt(pi^2 + ln^2 e).
double dampingFromRestitution(double restitution);

/// The automatic step stays below this fraction of the damped stability limit
/// (ref §7a: "lower for high damping ratios"). The limit is that of one contact;
/// in a dense pile with beta = 1 at 0.8 of it the contact network was just
/// unstable (its step ratio 1.04, the pile crept, tests/stability), at 0.6 it is
/// 0.90 (quiet). With the study's beta = 0.11 the spring criterion (safety 0.4)
/// is 0.58 (spheres) to 0.64 (four-ball clumps: capped here) of the limit.
inline constexpr double kDampedMargin = 0.6;
/// The dashpot is counted this many times in the damped limit: a ball pressed
/// from both sides (the fastest mode of a chain, and of a column in a pile) is
/// damped by two contacts at once. With one, a dense pile with beta_n = 1 at the
/// automatic step crept by 0.9 radius in 2e4 steps (tests/stability).
inline constexpr double kDashpotMultiplicity = 2.0;

struct TimestepAudit {
  double spring_translational = 0.0;  // s  sqrt(m/k_n), stiffest pair of the lightest body
  double spring_rotational = 0.0;     // s  sqrt(I/(k_s L^2)), L = lever (R for a sphere)
  // s  parallel bonds (0 without): each ball against the sum of its bonds'
  // springs (ref §7a: k_tran and k_rot are sums over the contacts and bonds
  // acting on a body): sqrt(m / sum k_n A), and sqrt(I / sum (k_s A L^2 +
  // max(k_n I_b, k_s J_b))) with L the bond's lever (bonds hold a ball from
  // every side at once, unlike the contacts of a pile, so their sum counts).
  double bond_translational = 0.0;
  double bond_rotational = 0.0;
  double critical = 0.0;              // s  min of the springs (contacts and bonds)
  double rayleigh = 0.0;              // s  0 when no shear modulus is given (linear law)
  double hertz_contact_time = 0.0;    // s  at impact_velocity; 0 for the linear law
  double linear_contact_time = 0.0;   // s  lightest ball on its stiffest partner; 0 for Hertz
  // s  exact leapfrog limit of one contact with its dashpots (normal and sticking
  // shear modes, both bodies' translation and rotation, the partner that damps
  // hardest); 0 when the contacts are undamped. See dampedStabilityLimit.
  double damped_limit = 0.0;
  double automatic = 0.0;             // s  min(safety_factor * critical, kDampedMargin * damped_limit)
  double chosen = 0.0;                // s
  double ratio() const { return chosen / critical; }
  std::string describe(const TimestepSettings& settings) const;
};

/// Audits the step for the given balls against every partner they can meet
/// (other balls' materials and every wall) and their intact bonds. Throws
/// std::invalid_argument when a requested dt exceeds the automatic one (unless
/// timestep.allow_unsafe).
TimestepAudit auditTimestep(const Model& model, const ParticleState& particles, const BondState& bonds = {});

}  // namespace rocklab::sim
