#include "../world_impl.h"

#include <cmath>
#include <sstream>

namespace rocklab::sim {

using detail::PairProps;

// Stage 7 (part), the contact-network step check (contact_spectrum.h): every
// touching contact and contribution spring as a spring-dashpot between rigid
// bodies; power iteration for the fastest mode; stops when dt exceeds its
// stable step. Reads: the contact lists and history, positions, clumps.
// Writes: guard.spectrum and guard.network (reused), stats.network_*.

// The touching contacts as springs between rigid bodies (free balls and clumps),
// for the step check. A shear spring counts only while it sticks.
template <class Law>
void World::Impl::buildContactNetwork(detail::ContactNetwork& net) const {
  net.bodies.clear();  // capacity kept between checks
  net.body_names.clear();
  net.contacts.clear();
  const std::size_t n = p.size();
  const ClumpState& k = p.clumps;
  std::vector<std::int32_t> body_of(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (isMember(i)) continue;
    body_of[i] = static_cast<std::int32_t>(net.bodies.size());
    const double inertia = 1.0 / p.inv_inertia[i];
    net.bodies.push_back({p.inv_mass[i], inertia * geometry::Mat3::Identity(),
                          p.inv_inertia[i] * geometry::Mat3::Identity()});
    net.body_names.push_back("particle " + std::to_string(p.id[i]));
  }
  const auto first_clump = static_cast<std::int32_t>(net.bodies.size());
  for (std::size_t c = 0; c < k.size(); ++c) {
    const geometry::Mat3 r = k.orientation[c].toRotationMatrix();
    net.bodies.push_back({1.0 / k.mass[c], r * k.inertia[c].asDiagonal() * r.transpose(),
                          r * k.inertia[c].cwiseInverse().asDiagonal() * r.transpose()});
    net.body_names.push_back("clump " + std::to_string(k.id[c]));
  }
  if (has_clumps)
    for (std::size_t i = 0; i < n; ++i)
      if (isMember(i)) body_of[i] = first_clump + p.clump[i];
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
    net.contacts.push_back(c);
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
    for (std::uint32_t w = nb.wall_offset[i]; w < nb.wall_offset[i + 1]; ++w) {
      if (!history.wall_touch[w]) continue;
      const std::uint32_t wk = nb.wall_index[w];
      ContactPoint touch;
      if (!ballWallTouch(walls[wk], model.walls[wk], p.position[i], ri, touch)) continue;
      const double overlap = wallOverlap(touch, w);
      if (overlap <= 0) continue;
      add(i, -1, touch.normal, touch.point, touch.point, overlap, ri, p.mass[i], wallProps(i, wk),
          history.wall_shear[w]);
    }
  }
  // Springs of the bonds and the force contributions: checked like contacts
  // (the peers that left bonds out were asked for it by their users).
  if (contributions.empty() && bonds.intact == 0) return;
  std::vector<NetworkSpring> springs;
  if (bonds.intact > 0) bondSprings(springs);
  const ForceInput in = forceInput();
  for (const auto& contribution : contributions) contribution->networkSprings(in, springs);
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
    net.contacts.push_back(c);
  }
}

void World::Impl::checkNetworkStep() {
  if (model.watchdog.network_iterations <= 0) return;
  detail::ContactNetwork& net = guard.network;
  if (model.contact.law == ContactLaw::Linear)
    buildContactNetwork<detail::LinearLaw>(net);
  else
    buildContactNetwork<detail::HertzMindlinLaw>(net);
  detail::iterateSpectrum(net, 2.0 / dt, model.watchdog.network_iterations, guard.spectrum);
  // Stable while L < 4 / dt^2 (contact_spectrum.h): the ratio dt / (2 / sqrt(L)).
  const double ratio = 0.5 * dt * std::sqrt(guard.spectrum.eigenvalue);
  ++stats.network_checks;
  stats.network_step_ratio = std::max(stats.network_step_ratio, ratio);
  if (ratio <= 1.0) return;
  const double omega = std::sqrt(guard.spectrum.stiffness);
  const double stable = detail::stableStep(guard.spectrum.stiffness, guard.spectrum.damping);
  std::ostringstream s;
  s << "watchdog: at t = " << fmtNum(time) << " s (step " << step << ") the step is unstable for the contact "
    << "network: its fastest mode (" << net.contacts.size() << " touching contacts; largest share on "
    << (guard.spectrum.body >= 0 ? net.body_names[static_cast<std::size_t>(guard.spectrum.body)] : std::string("none"))
    << ") has omega = " << fmtNum(omega) << " rad/s and dashpots " << fmtNum(guard.spectrum.damping)
    << " 1/s, stable only for dt < " << fmtNum(stable) << " s (" << fmtNum(stable / audit.critical)
    << " x critical). Sticking contacts would creep and slip without a blow-up, unseen by the energy check. "
       "The critical step counts one contact per body; a body pressed by several, a stuck shear spring that "
       "also turns it, and their dashpots make it vibrate faster (ref §7a). "
    << stepAdvice();
  throw WatchdogError(s.str());
}

}  // namespace rocklab::sim
