#include <sstream>

#include "../world_impl.h"

namespace rocklab::sim {

// Stage 4 (part), contact bonds (bonds.h, dem-models.md §8.1): a glue point with
// a normal and a shear spring at the contact, which while intact replaces the
// pair's ordinary contact (the pair is kept out of nb.pairs: neighbours.cpp).
// Reads: positions at t, velocities and spins at t - dt/2, materials, the contact
// model; bonds.state. Writes: bond k's own entries of bonds.state and of the
// per-bond scratch (force_b, torque_a/b, handover_shear): called in parallel over bonds.
//
// The pair is evaluated as the contact pass orders it (i = min(a, b), j = max):
// the same geometry, relative velocity, arms and spring convention (force on i),
// so a broken bond hands its ordinary contact a state, and in its breaking step a
// force, bit for bit like the pass's own.

template <class Law>
std::uint8_t World::Impl::contactBondStep(std::size_t k, StepChecks& c) {
  BondState& s = bonds.state;
  const std::uint32_t a = s.a[k], b = s.b[k];
  const bool a_first = a < b;
  const std::uint32_t i = a_first ? a : b, j = a_first ? b : a;
  const Vec3 xi = p.position[i], xj = p.position[j];
  const double ri = p.radius[i], rj = p.radius[j];
  ContactPoint touch;
  ballBallGeometry(xi, xj, ri, rj, touch);  // overlap < 0: the bond spans a gap
  detail::ContactGeometry g;
  g.normal = touch.normal;
  g.overlap = touch.overlap;
  const Vec3 ai = touch.point - xi, aj = touch.point - xj;
  g.rel_velocity = (p.velocity[j] + p.omega[j].cross(aj)) - (p.velocity[i] + p.omega[i].cross(ai));
  g.r_tilde = effectiveRadius(ri, rj);  // Eq 2-24
  g.damping_mass = detail::dampingMass(model.contact.damping_mass, p.mass[i], p.mass[j]);
  // The table keeps the shear force on b; the contact law's spring is the force on i.
  const Vec3 spring_before = a_first ? Vec3(-s.shear_force[k]) : s.shear_force[k];
  Vec3 spring = spring_before;
  double fn = 0.0;  // N, compression > 0
  Vec3 force_i = detail::evaluateBondedContact(s.spring_normal[k], s.spring_shear[k],
                                               s.reference_overlap[k], model.contact, g, dt, spring, fn)
                     .force;
  s.normal[k] = a_first ? g.normal : Vec3(-g.normal);
  s.normal_force[k] = fn;
  s.shear_force[k] = a_first ? Vec3(-spring) : spring;

  std::uint8_t broke = 0;
  if (-fn >= s.tensile_strength[k]) {
    // Tension reaches F_c^n (§8.1): the bond breaks, normal and shear force are zero.
    broke = Bonds::kTensile;
    force_i.setZero();
    bonds.handover_shear[k].setZero();
  } else if (spring.norm() >= s.shear_strength[k]) {
    // Shear reaches F_c^s (§8.1): the bond breaks and the ordinary contact takes
    // over in this step from the spring the bond held. Compressive and within the
    // friction limit, it gives the bond's forces (kept); beyond, its slip rule
    // (Eq 2-39) cuts the shear force; apart (no compression), it carries nothing.
    broke = Bonds::kShear;
    Vec3 contact_spring = spring_before;
    if (touch.overlap > 0) {
      force_i = detail::evaluateContact<Law>(pairProps(i, j), model.contact, g, dt, contact_spring).force;
      broke |= Bonds::kActs;
    } else {
      force_i.setZero();
      contact_spring.setZero();
    }
    bonds.handover_shear[k] = contact_spring;
  }
  const double r_small = std::min(ri, rj);
  if (touch.overlap > model.watchdog.max_overlap_fraction * r_small)
    mergeWorst(c, touch.overlap / r_small, (std::uint64_t(i) << 32) | j);
  // As the force pass's evaluateTouchingPair: force on i, its arm; minus it on j.
  const Vec3 ti = ai.cross(force_i);
  const Vec3 force_j = -force_i;
  const Vec3 tj = aj.cross(force_j);
  bonds.force_b[k] = a_first ? force_j : force_i;
  bonds.torque_a[k] = a_first ? ti : tj;
  bonds.torque_b[k] = a_first ? tj : ti;
  return broke;
}

std::uint8_t World::Impl::contactBondStepAny(std::size_t k, StepChecks& c) {
  return model.contact.law == ContactLaw::Linear ? contactBondStep<detail::LinearLaw>(k, c)
                                                 : contactBondStep<detail::HertzMindlinLaw>(k, c);
}

/// The springs of contact bond k at the configuration the world starts from.
/// Linear law: the pair's K^n, K^s (Eq 2-20, 2-21), the normal spring unstressed
/// at touch, or at the gap when bonded apart. Hertz: the tangent stiffnesses at
/// the bonding overlap U0 (dF/dU = 3/2 K^n of Eq 2-22, K^s of Eq 2-23 at F(U0)),
/// the normal spring through F(U0) at U0; zero at touch, so U0 must be > 0.
void World::Impl::installContactBond(std::size_t k) {
  BondState& s = bonds.state;
  const std::uint32_t i = std::min(s.a[k], s.b[k]), j = std::max(s.a[k], s.b[k]);
  ContactPoint touch;
  ballBallGeometry(p.position[i], p.position[j], p.radius[i], p.radius[j], touch);
  const double u0 = touch.overlap;  // m
  const detail::PairProps props =
      detail::ballBallProps(model.materials.at(p.material[i]), model.materials.at(p.material[j]));
  s.radius[k] = 0.0;  // zero size
  if (model.contact.law == ContactLaw::Linear) {
    s.spring_normal[k] = props.kn;
    s.spring_shear[k] = props.ks;
    s.reference_overlap[k] = std::min(u0, 0.0);
    return;
  }
  if (!(u0 > 0)) {
    std::ostringstream e;
    e << "bond " << k << ": a contact bond under the Hertz law needs its balls " << s.a[k] << " and "
      << s.b[k] << " to overlap when bonded (its springs are the Hertz tangent stiffnesses at the "
      << "bonding overlap, zero at touch); they are " << fmtNum(-u0) << " m apart";
    throw std::invalid_argument(e.str());
  }
  const double r_tilde = effectiveRadius(p.radius[i], p.radius[j]);
  double secant, tangent;
  detail::HertzMindlinLaw::normal(props, u0, r_tilde, secant, tangent);
  const double f0 = secant * u0;
  s.spring_normal[k] = tangent;
  s.spring_shear[k] = detail::HertzMindlinLaw::shear(props, secant);
  s.reference_overlap[k] = u0 - f0 / tangent;  // U0 / 3
}

/// Keys (min << 32 | max, ascending) of the pairs held by intact contact bonds.
std::vector<std::uint64_t> World::Impl::contactBondedPairs() const {
  const BondState& s = bonds.state;
  std::vector<std::uint64_t> keys;
  keys.reserve(bonds.contact_intact);
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!s.intact[k] || s.kind[k] != static_cast<std::uint8_t>(BondKind::Contact)) continue;
    const std::uint64_t i = std::min(s.a[k], s.b[k]), j = std::max(s.a[k], s.b[k]);
    keys.push_back((i << 32) | j);
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}

/// The pairs of contact bonds broken since the last build start their ordinary
/// contact from the shear spring the bond handed over (right after a rebuild).
void World::Impl::takeHandovers() {
  for (const PairHistory& h : bonds.handover) {
    const auto b = nb.pairs.partner.begin() + nb.pairs.row_offset[h.i];
    const auto e = nb.pairs.partner.begin() + nb.pairs.row_offset[h.i + 1];
    const auto it = std::lower_bound(b, e, h.j);
    if (it != e && *it == h.j) history.pair_shear[static_cast<std::size_t>(it - nb.pairs.partner.begin())] = h.shear;
  }
  bonds.handover.clear();
}

/// Elastic energy of intact contact bond k: F_n^2 / (2 k_n) + |F_s|^2 / (2 k_s) (J).
double World::Impl::contactBondEnergy(std::size_t k) const {
  const BondState& s = bonds.state;
  double e = 0.5 * s.normal_force[k] * s.normal_force[k] / s.spring_normal[k];
  if (s.spring_shear[k] > 0) e += 0.5 * s.shear_force[k].squaredNorm() / s.spring_shear[k];
  return e;
}

/// Intact contact bond k as a spring-dashpot of the contact network (both dashpots
/// of evaluateBondedContact: it always sticks).
NetworkSpring World::Impl::contactBondSpring(std::size_t k) const {
  const BondState& s = bonds.state;
  const std::uint32_t a = s.a[k], b = s.b[k];
  NetworkSpring spring;
  spring.a = a;
  spring.b = b;
  spring.normal = s.normal[k];
  spring.point =
      bondPoint(p.position[a], p.radius[a], p.radius[b], s.normal[k], (p.position[b] - p.position[a]).norm());
  spring.kn = s.spring_normal[k];
  spring.ks = s.spring_shear[k];
  const double m = detail::dampingMass(model.contact.damping_mass, p.mass[a], p.mass[b]);
  spring.cn = detail::dashpot(model.contact.damping_normal, m, spring.kn);
  spring.cs = detail::dashpot(model.contact.damping_shear, m, spring.ks);
  return spring;
}

}  // namespace rocklab::sim
