#include "../world_impl.h"

#include <cmath>
#include <sstream>

namespace rocklab::sim {

using detail::PairProps;

// Stage 7 (part), the contact-network step check (contact_spectrum.h): every
// touching contact and contribution spring as a spring-dashpot between rigid
// bodies; power iteration for the fastest mode; stops when dt exceeds its
// stable step. Reads: the contact lists and history, positions, clumps.
// Writes: guard.spectrum, stats.network_*. The bodies are listed for the
// check only and the contacts visited, not stored (contact_spectrum.h): the
// run's memory at its peak does not include the check.

// The bodies of the check (free balls, then clumps); returns each ball's body.
std::vector<std::int32_t> World::Impl::networkBodies(detail::ContactNetwork& net) const {
  const std::size_t n = p.size();
  const ClumpState& k = p.clumps;
  std::vector<std::int32_t> body_of(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (isMember(i)) continue;
    body_of[i] = static_cast<std::int32_t>(net.bodies.size());
    net.bodies.push_back({p.inv_mass[i], p.inv_inertia[i], static_cast<std::int32_t>(i), -1});
  }
  const auto first_clump = static_cast<std::int32_t>(net.bodies.size());
  for (std::size_t c = 0; c < k.size(); ++c) {
    const geometry::Mat3 r = k.orientation[c].toRotationMatrix();
    const auto index = static_cast<std::int32_t>(c);
    net.bodies.push_back({1.0 / k.mass[c], 0.0, index, index});
    net.clump_inertia.push_back(r * k.inertia[c].asDiagonal() * r.transpose());
    net.clump_inv_inertia.push_back(r * k.inertia[c].cwiseInverse().asDiagonal() * r.transpose());
  }
  if (has_clumps)
    for (std::size_t i = 0; i < n; ++i)
      if (isMember(i)) body_of[i] = first_clump + p.clump[i];
  return body_of;
}

// Hands every touching contact to `visit` as a spring-dashpot between rigid
// bodies, in the order of the lists. A shear spring counts only while it sticks.
template <class Law>
void World::Impl::visitTouchingContacts(const std::vector<std::int32_t>& body_of,
                                        const detail::ContactVisitor& visit) const {
  const std::size_t n = p.size();
  const ClumpState& k = p.clumps;
  auto centre = [&](std::size_t i) { return isMember(i) ? k.position[p.clump[i]] : p.position[i]; };
  const ContactModel& cm = model.contact;
  auto add = [&](std::size_t i, std::int32_t b, const Vec3& normal, const Vec3& cp, const Vec3& centre_b,
                 double overlap, double r_tilde, double damping_mass, const PairProps& props, const Vec3& shear) {
    double secant, tangent;
    Law::normal(props, overlap, r_tilde, secant, tangent);
    const double fn = secant * overlap;
    const double limit = props.friction * fn;
    const bool sticks = shear.squaredNorm() < limit * limit * (1.0 - 1e-9);
    detail::NetworkContact c;
    c.a = body_of[i];
    c.b = b;
    c.normal = normal;
    c.lever_a = cp - centre(i);
    c.lever_b = cp - centre_b;
    c.kn = tangent;
    c.ks = sticks ? Law::shear(props, secant) : 0.0;
    // The dashpots of evaluateContact (Eq 2-16..2-18); the shear one only while sticking.
    c.cn = detail::dashpot(cm.damping_normal, damping_mass, c.kn);
    c.cs = detail::dashpot(cm.damping_shear, damping_mass, c.ks);
    visit(c);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double ri = p.radius[i];
    for (std::uint32_t q = nb.pairs.row_offset[i]; q < nb.pairs.row_offset[i + 1]; ++q) {
      if (!history.pair_touch[q]) continue;
      const std::uint32_t j = nb.pairs.partner[q];
      if (body_of[i] == body_of[j]) continue;  // members of one clump
      ContactPoint touch;
      if (!ballBallTouch(p.position[i], p.position[j], ri, p.radius[j], touch)) continue;
      const double overlap = pairOverlap(touch, q);
      if (overlap <= 0) continue;
      const double md = detail::dampingMass(cm.damping_mass, p.mass[i], p.mass[j]);
      add(i, body_of[j], touch.normal, touch.point, centre(j), overlap, effectiveRadius(ri, p.radius[j]), md,
          pairProps(i, j), history.pair_shear[q]);
    }
    forEachWallTouch(walls, i, [&](std::uint32_t w, std::uint32_t wk, const ContactPoint* touch) {
      if (!history.wall_touch[w] || !touch) return;
      const double overlap = wallOverlap(*touch, w);
      if (overlap <= 0) return;
      add(i, -1, touch->normal, touch->point, touch->point, overlap, ri, p.mass[i], wallProps(i, wk),
          history.wall_shear[w]);
    });
  }
}

void World::Impl::checkNetworkStep() {
  if (model.watchdog.network_iterations <= 0) return;
  detail::ContactNetwork net;
  const std::vector<std::int32_t> body_of = networkBodies(net);
  // Springs of the bonds and the force contributions: checked like contacts
  // (the peers that left bonds out were asked for it by their users). Their
  // number is the bonds', not the balls', so they are listed once per check.
  std::vector<NetworkSpring> springs;
  if (bonds.intact > 0) bondSprings(springs);
  if (!contributions.empty()) {
    const ForceInput in = forceInput();
    for (const auto& contribution : contributions) contribution->networkSprings(in, springs);
  }
  auto centre = [&](std::size_t i) { return isMember(i) ? p.clumps.position[p.clump[i]] : p.position[i]; };
  const detail::ContactSource contacts = [&](const detail::ContactVisitor& visit) {
    if (model.contact.law == ContactLaw::Linear)
      visitTouchingContacts<detail::LinearLaw>(body_of, visit);
    else
      visitTouchingContacts<detail::HertzMindlinLaw>(body_of, visit);
    for (const NetworkSpring& s : springs) {
      if (body_of[s.a] == body_of[s.b]) continue;  // inside one rigid clump
      detail::NetworkContact c;
      c.a = body_of[s.a];
      c.b = body_of[s.b];
      c.normal = s.normal;
      c.lever_a = s.point - centre(s.a);
      c.lever_b = s.point - centre(s.b);
      c.kn = s.kn;
      c.ks = s.ks;
      c.cn = s.cn;
      c.cs = s.cs;
      visit(c);
    }
  };
  detail::iterateSpectrum(net, contacts, 2.0 / dt, model.watchdog.network_iterations, guard.spectrum);
  // Stable while L < 4 / dt^2 (contact_spectrum.h): the ratio dt / (2 / sqrt(L)).
  const double ratio = 0.5 * dt * std::sqrt(guard.spectrum.eigenvalue);
  ++stats.network_checks;
  stats.network_step_ratio = std::max(stats.network_step_ratio, ratio);
  if (ratio <= 1.0) return;
  auto bodyName = [&](std::int32_t body) -> std::string {
    if (body < 0) return "none";
    const detail::NetworkBody& b = net.bodies[static_cast<std::size_t>(body)];
    const auto source = static_cast<std::size_t>(b.source);
    return b.clump < 0 ? "particle " + std::to_string(p.id[source]) : "clump " + std::to_string(p.clumps.id[source]);
  };
  const double omega = std::sqrt(guard.spectrum.stiffness);
  const double stable = detail::stableStep(guard.spectrum.stiffness, guard.spectrum.damping);
  std::ostringstream s;
  s << "watchdog: at t = " << fmtNum(time) << " s (step " << step << ") the step is unstable for the contact "
    << "network: its fastest mode (" << guard.spectrum.contacts << " touching contacts; largest share on "
    << bodyName(guard.spectrum.body)
    << ") has omega = " << fmtNum(omega) << " rad/s and dashpots " << fmtNum(guard.spectrum.damping)
    << " 1/s, stable only for dt < " << fmtNum(stable) << " s (" << fmtNum(stable / audit.critical)
    << " x critical). Sticking contacts would creep and slip without a blow-up, unseen by the energy check. "
       "The critical step counts one contact per body; a body pressed by several, a stuck shear spring that "
       "also turns it, and their dashpots make it vibrate faster (ref §7a). "
    << stepAdvice();
  throw WatchdogError(s.str());
}

}  // namespace rocklab::sim
