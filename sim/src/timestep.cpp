#include "rocklab/sim/timestep.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "contact_kernel.h"

namespace rocklab::sim {

double springCriticalStep(double mass, double inertia, double radius, double kn, double ks) {
  const double inf = std::numeric_limits<double>::infinity();
  const double translational = kn > 0 ? std::sqrt(mass / kn) : inf;
  const double rotational = ks > 0 ? std::sqrt(inertia / (ks * radius * radius)) : inf;
  return std::min(translational, rotational);
}

double rayleighStep(double radius, double density, double shear_modulus, double poisson) {
  return std::numbers::pi * radius * std::sqrt(density / shear_modulus) /
         (0.1631 * poisson + 0.8766);
}

double hertzCoefficient(double shear_modulus, double poisson, double r_tilde) {
  return 2.0 * shear_modulus * std::sqrt(2.0 * r_tilde) / (3.0 * (1.0 - poisson));  // Eq 2-22
}

double hertzMaxOverlap(double mass, double c, double velocity) {
  // Energy balance: m v^2 / 2 = integral of c d^(3/2) = 2/5 c d^(5/2).
  return std::pow(5.0 * mass * velocity * velocity / (4.0 * c), 0.4);
}

double hertzContactTime(double mass, double c, double velocity) {
  // t = 2 (d_max / v) * integral_0^1 dx / sqrt(1 - x^(5/2)) = 2.9432 d_max / v.
  return 2.9432 * hertzMaxOverlap(mass, c, velocity) / velocity;
}

double linearContactTime(double mass, double k, double beta) {
  return std::numbers::pi / (std::sqrt(k / mass) * std::sqrt(1.0 - beta * beta));
}

double dampedStabilityLimit(double k, double c, double inv_mass) {
  const double b = c * inv_mass;
  return 4.0 / (b + std::sqrt(b * b + 4.0 * k * inv_mass));
}

double restitutionFromDamping(double beta) {
  return std::exp(-beta * std::numbers::pi / std::sqrt(1.0 - beta * beta));  // Eq 4-4
}

double dampingFromRestitution(double restitution) {
  const double l = std::log(restitution);
  return -l / std::sqrt(std::numbers::pi * std::numbers::pi + l * l);
}

std::string TimestepAudit::describe(const TimestepSettings& settings) const {
  std::ostringstream s;
  s.precision(4);
  s << "time step audit:\n";
  s << "  spring, translational sqrt(m/k_n)    " << spring_translational << " s\n";
  s << "  spring, rotational sqrt(I/(k_s L^2)) " << spring_rotational << " s\n";
  if (bond_translational > 0)
    s << "  bonds, translational sqrt(m/sum k_n A) " << bond_translational << " s\n"
      << "  bonds, rotational                    " << bond_rotational << " s\n";
  if (rayleigh > 0) s << "  Rayleigh                             " << rayleigh << " s\n";
  if (hertz_contact_time > 0)
    s << "  Hertz contact time at " << settings.impact_velocity << " m/s        "
      << hertz_contact_time << " s (" << hertz_contact_time / chosen << " steps)\n";
  if (linear_contact_time > 0)
    s << "  linear contact time                  " << linear_contact_time << " s ("
      << linear_contact_time / chosen << " steps)\n";
  s << "  critical (min of springs)            " << critical << " s\n";
  if (damped_limit > 0)
    s << "  damped stability limit (dashpots)    " << damped_limit << " s\n";
  if (automatic < settings.safety_factor * critical)
    s << "  automatic = " << kDampedMargin << " x damped limit        " << automatic << " s (below "
      << settings.safety_factor << " x critical: capped by the dashpots)\n";
  else
    s << "  automatic = " << settings.safety_factor << " x critical        " << automatic << " s\n";
  s << "  chosen dt                            " << chosen << " s  (dt/dt_crit = " << ratio()
    << (settings.dt > 0 ? ", set by timestep.dt" : ", automatic") << ")";
  return s.str();
}

namespace {

/// The bond lines of the audit (TimestepAudit::bond_translational, _rotational).
void auditBonds(const Model& model, const ParticleState& p, const BondState& bonds, TimestepAudit& a) {
  const std::size_t n = p.size();
  std::vector<double> k_tran(n, 0.0), k_rot(n, 0.0);
  const double kn = model.bonds.normal_stiffness, ks = model.bonds.shear_stiffness;
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (!bonds.intact[k]) continue;
    if (bonds.kind[k] == static_cast<std::uint8_t>(BondKind::Contact)) {
      // A contact bond (§8.1): its normal spring, and its shear spring on the lever.
      for (const std::uint32_t i : {bonds.a[k], bonds.b[k]}) {
        k_tran[i] += bonds.spring_normal[k];
        k_rot[i] += bonds.spring_shear[k] * p.radius[i] * p.radius[i];
      }
      continue;
    }
    const BondDisc d = bondDisc(bonds.radius[k]);
    const double bend_twist = std::max(kn * d.inertia, ks * d.polar);
    for (const std::uint32_t i : {bonds.a[k], bonds.b[k]}) {
      k_tran[i] += kn * d.area;
      // Lever: the ball's radius (its centre to the bond) for a sphere.
      k_rot[i] += ks * d.area * p.radius[i] * p.radius[i] + bend_twist;
    }
  }
  const double inf = std::numeric_limits<double>::infinity();
  double tran = inf, rot = inf;
  for (std::size_t i = 0; i < n; ++i) {
    if (k_tran[i] > 0) tran = std::min(tran, std::sqrt(p.mass[i] / k_tran[i]));
    if (k_rot[i] > 0) rot = std::min(rot, std::sqrt(1.0 / (p.inv_inertia[i] * k_rot[i])));
  }
  if (std::isfinite(tran)) a.bond_translational = tran;
  if (std::isfinite(rot)) a.bond_rotational = rot;
}

}  // namespace

TimestepAudit auditTimestep(const Model& model, const ParticleState& particles, const BondState& bonds) {
  using detail::PairProps;
  const double inf = std::numeric_limits<double>::infinity();
  TimestepAudit a;
  a.spring_translational = a.spring_rotational = inf;
  const bool hertz = model.contact.law == ContactLaw::HertzMindlin;
  const double v = model.timestep.impact_velocity;

  // Materials actually present among the balls, and every wall's material.
  std::vector<bool> ball_material(model.materials.size(), false);
  for (int m : particles.material) ball_material[m] = true;
  double lightest = inf, lightest_k = 0.0;
  // Damped stability limit (see dampedStabilityLimit). Each ball's inverse masses
  // of the normal and the sticking-shear mode at a contact: 1/m + e^2/I with e the
  // lever of the force about the centre (0 normal, R shear for a sphere; clump
  // members: their offset, and offset + R). Partners: for each material present,
  // the lightest and the heaviest ball of that material, on the stiffness of that
  // pair of materials (a ball of one material never meets another's spring: a
  // 9 mg fragment on its soft class stiffness is not damped like a rock on
  // rock), or a wall (immovable, dashpot on the ball's mass). A partner of a mass
  // between the two is never harder: with the reduced-mass dashpot both the
  // damping rate and the spring rate fall as the partner gets heavier, with the
  // average-mass one the damping rate falls then rises (one minimum, at twice the
  // ball's mass) while the spring rate falls, and the limit over a mass range is
  // then at one of its ends.
  const ContactModel& cm = model.contact;
  const bool damped = cm.damping_normal > 0 || cm.damping_shear > 0;
  double damped_limit = inf;
  struct Body { double m, inv_n, inv_t; };
  std::vector<Body> body(particles.size());
  double rayleigh = inf, hertz_time = inf;

  // Lever of a contact about the body's centre: the radius for a sphere, the
  // member's distance from the centre of mass plus its radius for a clump.
  std::vector<double> lever(particles.radius);
  const ClumpState& clumps = particles.clumps;
  for (std::size_t m = 0; m < clumps.member_ball.size(); ++m)
    lever[clumps.member_ball[m]] += clumps.member_offset[m].norm();

  // The lightest and the heaviest ball of each material (rows; none: npos).
  constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> light(model.materials.size(), npos), heavy(model.materials.size(), npos);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const double m = particles.mass[i], r = particles.radius[i], inv_i = particles.inv_inertia[i];
    const double offset = lever[i] - r;
    body[i] = {m, 1.0 / m + offset * offset * inv_i, 1.0 / m + lever[i] * lever[i] * inv_i};
    const auto mat = static_cast<std::size_t>(particles.material[i]);
    if (light[mat] == npos || m < particles.mass[light[mat]]) light[mat] = i;
    if (heavy[mat] == npos || m > particles.mass[heavy[mat]]) heavy[mat] = i;
  }
  auto dampedModes = [&](double kn, double ks, const Body& self, const Body* b) {
    const double inv_n = self.inv_n + (b ? b->inv_n : 0.0), inv_t = self.inv_t + (b ? b->inv_t : 0.0);
    double md = self.m;  // ball–wall: the ball's mass (Eq 2-18)
    if (b) md = detail::dampingMass(cm.damping_mass, self.m, b->m);
    if (kn > 0) {
      const double c = detail::dashpot(cm.damping_normal, md, kn);
      damped_limit = std::min(damped_limit, dampedStabilityLimit(kn, kDashpotMultiplicity * c, inv_n));
    }
    if (ks > 0) {
      const double c = detail::dashpot(cm.damping_shear, md, ks);
      damped_limit = std::min(damped_limit, dampedStabilityLimit(ks, kDashpotMultiplicity * c, inv_t));
    }
  };

  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Material& mi = model.materials[particles.material[i]];
    const double m = particles.mass[i], r = particles.radius[i], arm = lever[i];
    const double inertia = 1.0 / particles.inv_inertia[i];
    // partner_material: the other ball's material (-1: a wall).
    auto consider = [&](const PairProps& p, double m_star, int partner_material) {
      double kn = p.kn, ks = p.ks;
      if (hertz) {
        // Tangent stiffnesses at the deepest overlap of an impact at `v`.
        const double c = p.hertz_cn * std::sqrt(r);
        const double d = hertzMaxOverlap(m_star, c, v);
        kn = 1.5 * c * std::sqrt(d);
        ks = p.hertz_ks * std::cbrt(r * c * d * std::sqrt(d));
        hertz_time = std::min(hertz_time, hertzContactTime(m_star, c, v));
      }
      a.spring_translational = std::min(a.spring_translational, std::sqrt(m / kn));
      a.spring_rotational = std::min(a.spring_rotational, std::sqrt(inertia / (ks * arm * arm)));
      if (damped) {
        if (partner_material < 0) {
          dampedModes(kn, ks, body[i], nullptr);
        } else {
          const auto k = static_cast<std::size_t>(partner_material);
          for (std::size_t partner : {light[k], heavy[k]}) dampedModes(kn, ks, body[i], &body[partner]);
          // A ball like this one (a clump's lever is not its mass: not bounded by the ends).
          if (k == static_cast<std::size_t>(particles.material[i])) dampedModes(kn, ks, body[i], &body[i]);
        }
      }
      if (m < lightest || (m == lightest && kn > lightest_k)) {
        lightest = m;
        lightest_k = kn;
      }
    };
    for (std::size_t k = 0; k < model.materials.size(); ++k)
      if (ball_material[k]) consider(detail::ballBallProps(mi, model.materials[k]), 0.5 * m, static_cast<int>(k));
    for (const Wall& w : model.walls) consider(detail::ballWallProps(mi, model.materials[w.material]), m, -1);
    if (mi.shear_modulus > 0)
      rayleigh = std::min(rayleigh, rayleighStep(r, mi.density, mi.shear_modulus, mi.poisson));
  }
  a.critical = std::min(a.spring_translational, a.spring_rotational);
  auditBonds(model, particles, bonds, a);
  if (a.bond_translational > 0) a.critical = std::min({a.critical, a.bond_translational, a.bond_rotational});
  a.rayleigh = std::isfinite(rayleigh) ? rayleigh : 0.0;
  a.hertz_contact_time = std::isfinite(hertz_time) ? hertz_time : 0.0;
  if (!hertz && std::isfinite(lightest) && lightest_k > 0)
    a.linear_contact_time = linearContactTime(0.5 * lightest, lightest_k, model.contact.damping_normal);

  const TimestepSettings& ts = model.timestep;
  if (!std::isfinite(a.critical)) {
    // No ball can touch anything stiff (no balls, or no stiffness): nothing limits dt.
    if (ts.dt <= 0)
      throw std::invalid_argument(
          "timestep: no contact limits the step (no balls or zero stiffness); set timestep.dt");
    a.automatic = a.chosen = ts.dt;
    a.critical = inf;
    return a;
  }
  a.damped_limit = std::isfinite(damped_limit) ? damped_limit : 0.0;
  a.automatic = ts.safety_factor * a.critical;
  // Strong dashpots shrink the stable step below the spring criterion (ref §7a):
  // cap the automatic step at a margin below the exact damped limit.
  if (a.damped_limit > 0) a.automatic = std::min(a.automatic, kDampedMargin * a.damped_limit);
  a.chosen = a.automatic;
  if (ts.dt > 0) {
    if (ts.dt > a.automatic * (1.0 + 1e-12) && !ts.allow_unsafe) {
      std::ostringstream s;
      s << "timestep.dt = " << ts.dt << " s is larger than the automatic step " << a.automatic
        << " s (timestep.safety_factor " << ts.safety_factor << " x critical " << a.critical << " s"
        << (a.automatic < ts.safety_factor * a.critical ? ", capped by the damped stability limit" : "")
        << "); a scene may only lower the step: set timestep.dt <= " << a.automatic
        << " s, or timestep.allow_unsafe = true to force it";
      throw std::invalid_argument(s.str());
    }
    a.chosen = ts.dt;
  }
  return a;
}

}  // namespace rocklab::sim
