#pragma once
// The force–displacement law at one contact (ref §3–§6), specialised at compile
// time for the contact law. Internal to rocklab_sim.
#include <algorithm>
#include <cmath>

#include "rocklab/sim/model.h"

namespace rocklab::sim::detail {

using geometry::Vec3;

/// Constants of one material pair (ball–ball or ball–wall), computed once.
struct PairProps {
  double kn = 0.0;         // N/m  linear: series normal stiffness (Eq 2-20)
  double ks = 0.0;         // N/m  linear: series shear stiffness (Eq 2-21)
  double friction = 0.0;   // -    min of the two (ref §5)
  double hertz_cn = 0.0;   // N/m^2 Hertz: 2 G sqrt(2) / (3 (1 - nu)); times sqrt(R~) gives c
  double hertz_ks = 0.0;   // Hertz: 2 (3 G^2 (1 - nu))^(1/3) / (2 - nu); times (R~ F)^(1/3) gives k_s
  double hertz_ks_per_secant = 0.0;  // Hertz: hertz_ks / hertz_cn^(2/3); times K^n gives k_s (no cube root)
};

PairProps ballBallProps(const Material& a, const Material& b, FrictionRule rule = FrictionRule::Min);
/// Mirror rule for Hertz (ref §4.2): the ball's own G and nu; series springs for linear.
PairProps ballWallProps(const Material& ball, const Material& wall, FrictionRule rule = FrictionRule::Min);

/// Mass of a ball–ball dashpot (Eq 2-18); a ball–wall dashpot uses the ball's mass.
inline double dampingMass(DampingMass kind, double ma, double mb) {
  return kind == DampingMass::Average ? 0.5 * (ma + mb) : ma * mb / (ma + mb);
}

/// Dashpot of damping ratio `beta` on a spring k and a mass m (Eq 2-16, 2-17).
inline double dashpot(double beta, double mass, double k) { return 2.0 * beta * std::sqrt(mass * k); }

/// Input of one contact evaluation.
struct ContactGeometry {
  Vec3 normal;        // unit, from the body the force acts on (A) towards the other (B)
  double overlap;     // m, > 0
  Vec3 rel_velocity;  // m/s, velocity of B relative to A at the contact point
  double r_tilde;     // m, Eq 2-24 (ball–wall: the ball radius)
  double damping_mass;  // kg, Eq 2-18
};

struct ContactResult {
  Vec3 force;          // N on body A
};

struct LinearLaw {
  static constexpr bool kHertz = false;
  // Returns the secant normal stiffness K^n and the tangent one dF/dU.
  static void normal(const PairProps& p, double /*overlap*/, double /*r_tilde*/, double& secant,
                     double& tangent) {
    secant = tangent = p.kn;
  }
  /// The shear stiffness at a contact whose normal secant stiffness is `secant`.
  static double shear(const PairProps& p, double /*secant*/) { return p.ks; }
};

struct HertzMindlinLaw {
  static constexpr bool kHertz = true;
  static void normal(const PairProps& p, double overlap, double r_tilde, double& secant,
                     double& tangent) {
    // Eq 2-22: K^n = c sqrt(U^n), so F = c U^(3/2) and dF/dU = 3/2 K^n.
    secant = p.hertz_cn * std::sqrt(r_tilde * overlap);
    tangent = 1.5 * secant;
  }
  static double shear(const PairProps& p, double secant) {
    // Eq 2-23: K^s = 2 (3 G^2 (1 - nu) R~)^(1/3) / (2 - nu) |F^n|^(1/3). With the elastic
    // F^n = c sqrt(R~ U) U (Eq 2-22), (R~ F^n)^(1/3) = c^(1/3) sqrt(R~ U) = K^n / c^(2/3):
    // the same stiffness from the normal secant, without a cube root per contact and step.
    return p.hertz_ks_per_secant * secant;
  }
};

/// The stored shear force turned into the current tangent plane (normal n),
/// keeping its magnitude ([X] note (i) of §3).
[[gnu::always_inline]] inline void carryShear(Vec3& shear, const Vec3& n) {
  const double sn = shear.dot(n);
  if (sn != 0.0) {
    shear -= sn * n;
    const double new_mag2 = shear.squaredNorm();
    // Restore the magnitude: factor sqrt(1 + x), x = sn^2 / |s_t|^2. The normal
    // turns by a tiny angle per step, so x is tiny and the series
    // 1 + x/2 - x^2/8 is exact to round-off (error x^3/16) without a square root.
    if (new_mag2 > 0.0) {
      const double x = sn * sn / new_mag2;
      shear *= x < 1e-4 ? 1.0 + x * (0.5 - 0.125 * x) : std::sqrt(1.0 + x);
    }
  }
}

/// Evaluates one contact and updates its shear-force history `shear` (force on A).
template <class Law>
[[gnu::always_inline]] inline ContactResult evaluateContact(const PairProps& p, const ContactModel& cm,
                                     const ContactGeometry& g, double dt, Vec3& shear) {
  const Vec3& n = g.normal;
  double kn_secant, kn_tangent;
  Law::normal(p, g.overlap, g.r_tilde, kn_secant, kn_tangent);
  const double fn_elastic = kn_secant * g.overlap;  // Eq 2-2
  const double vn = g.rel_velocity.dot(n);          // < 0 while approaching
  const Vec3 vt = g.rel_velocity - vn * n;
  // Normal dashpot, Eq 2-16..2-18 with the tangent stiffness; may pull (recorded choice).
  const double cn =
      cm.damping_normal > 0 ? dashpot(cm.damping_normal, g.damping_mass, kn_tangent) : 0.0;
  const double fn_total = fn_elastic - cn * vn;

  // Shear spring: rotate the stored force into the current tangent plane keeping
  // its magnitude, then add the increment (Eq 2-3..2-5).
  carryShear(shear, n);
  const double ks = Law::shear(p, kn_secant);
  shear += (ks * dt) * vt;  // B moving along +vt drags A along +vt
  // Coulomb limit on the elastic normal force (Eq 2-39). While slipping, the
  // spring stays at the limit and the shear dashpot is off (PFC convention, [X]).
  const double limit = p.friction * fn_elastic;
  Vec3 ft;
  const double mag2 = shear.squaredNorm();
  if (mag2 > limit * limit) {
    shear *= limit / std::sqrt(mag2);
    ft = shear;
  } else {
    ft = shear;
    if (cm.damping_shear > 0) ft += dashpot(cm.damping_shear, g.damping_mass, ks) * vt;
  }
  return {ft - fn_total * n};
}

/// A contact bond (dem-models §8.1): the contact with its no-tension and slip
/// rules replaced by the bond's linear springs kn, ks (N/m). Normal force
/// kn (U - reference_overlap), positive in compression, for any overlap U (m; a
/// gap is U < 0), so separation builds tension; incremental shear spring
/// (Eq 2-3..2-5) with no Coulomb cap; both dashpots (Eq 2-16..2-18) always on,
/// as on a sticking contact. Updates `shear` (spring force on A, N) and returns
/// the force on A; `fn_elastic` is the normal spring's force (N).
inline ContactResult evaluateBondedContact(double kn, double ks, double reference_overlap,
                                           const ContactModel& cm, const ContactGeometry& g,
                                           double dt, Vec3& shear, double& fn_elastic) {
  const Vec3& n = g.normal;
  fn_elastic = kn * (g.overlap - reference_overlap);
  const double vn = g.rel_velocity.dot(n);
  const Vec3 vt = g.rel_velocity - vn * n;
  const double cn = cm.damping_normal > 0 ? dashpot(cm.damping_normal, g.damping_mass, kn) : 0.0;
  carryShear(shear, n);
  shear += (ks * dt) * vt;
  Vec3 ft = shear;
  if (cm.damping_shear > 0 && ks > 0) ft += dashpot(cm.damping_shear, g.damping_mass, ks) * vt;
  return {ft - (fn_elastic - cn * vn) * n};
}

/// Elastic energy stored at a contact (normal + shear spring).
template <class Law>
inline double elasticEnergy(const PairProps& p, double overlap, double r_tilde, const Vec3& shear) {
  double secant, tangent;
  Law::normal(p, overlap, r_tilde, secant, tangent);
  const double fn = secant * overlap;
  // Linear: F U / 2; Hertz: integral of c U^(3/2) = 2/5 F U.
  const double normal = (Law::kHertz ? 0.4 : 0.5) * fn * overlap;
  const double ks = Law::shear(p, secant);
  return normal + (ks > 0.0 ? 0.5 * shear.squaredNorm() / ks : 0.0);
}

}  // namespace rocklab::sim::detail
