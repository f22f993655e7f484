// The time-step formulas of the audit, each against an independent value.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "rocklab/sim/timestep.h"
#include "support.h"

using namespace rocklab;
using Catch::Matchers::WithinRel;
using geometry::Vec3;

TEST_CASE("restitution <-> damping ratio (Eq 4-4) and the study's numbers", "[timestep]") {
  CHECK_THAT(sim::restitutionFromDamping(0.0), WithinRel(1.0, 1e-15));
  for (double beta : {0.05, 0.11, 0.3, 0.7})
    CHECK_THAT(sim::dampingFromRestitution(sim::restitutionFromDamping(beta)), WithinRel(beta, 1e-12));
  // Reference §6.3: e = 0.72 gives beta = 0.104; beta = 0.11 gives e = 0.706.
  CHECK(sim::dampingFromRestitution(0.72) == Approx(0.104).margin(5e-4));
  CHECK(sim::restitutionFromDamping(0.11) == Approx(0.706).margin(5e-4));
}

TEST_CASE("spring - Rayleigh and contact-time formulas", "[timestep]") {
  const double m = 0.0114, r = 0.01, k = 1e9;
  const double inertia = 0.4 * m * r * r;
  CHECK_THAT(sim::springCriticalStep(m, inertia, r, k, 2 * k), WithinRel(std::sqrt(0.4 * m / (2 * k)), 1e-14));
  CHECK_THAT(sim::springCriticalStep(m, inertia, r, k, 0.1 * k), WithinRel(std::sqrt(m / k), 1e-14));
  // Rayleigh: for nu = 0.25 the Rayleigh speed is 0.9194 c_s (Viktorov).
  const double rho = 2700, g = 30e9, nu = 0.25;
  const double expected = std::numbers::pi * r / (0.9194 * std::sqrt(g / rho));
  CHECK_THAT(sim::rayleighStep(r, rho, g, nu), WithinRel(expected, 5e-3));  // the fit is 0.2 % off here
  // Linear contact time: half a damped period.
  CHECK_THAT(sim::linearContactTime(m, k, 0.0), WithinRel(std::numbers::pi * std::sqrt(m / k), 1e-14));
  // Hertz with the study's law reduces to classical Hertz for equal spheres:
  // c = (4/3) E* sqrt(R*), E* = G / (1 - nu), R* = R/2 (reference §4.2 check).
  const double c = sim::hertzCoefficient(g, nu, r);
  CHECK_THAT(c, WithinRel(4.0 / 3.0 * g / (1 - nu) * std::sqrt(r / 2), 1e-14));
  // Classical Hertz time 2.868 (m*^2 / (R* E*^2 v))^(1/5) (Johnson, Contact Mechanics §11.4).
  const double v = 2.0, m_star = m / 2, e_star = g / (1 - nu);
  const double classical = 2.868 * std::pow(m_star * m_star / (r / 2 * e_star * e_star * v), 0.2);
  CHECK_THAT(sim::hertzContactTime(m_star, c, v), WithinRel(classical, 2e-3));
}

TEST_CASE("audit: automatic step - scene may only lower it", "[timestep]") {
  auto model = test::linearModel(2e9);
  model.walls.push_back(test::floorPlane());
  std::vector<sim::SphereSpec> s{test::sphere({0, 0, 0.02}, 0.01)};
  sim::World w(model, s, 1);
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * 1e-6;
  // Stiffest partner: 2e9 in series with 2e9 = 1e9 N/m; rotation limits.
  CHECK_THAT(w.timestepAudit().critical, WithinRel(std::sqrt(0.4 * m / 1e9), 1e-12));
  CHECK_THAT(w.dt(), WithinRel(sim::TimestepSettings{}.safety_factor * w.timestepAudit().critical, 1e-12));

  model.timestep.dt = 1e-3;
  CHECK_THROWS_WITH(sim::World(model, s, 1), Catch::Contains("timestep.dt = 0.001 s is larger than the automatic step"));
  model.timestep.allow_unsafe = true;
  CHECK(sim::World(model, s, 1).dt() == 1e-3);
}

TEST_CASE("audit: the damped limit pairs each ball with the balls of each material on that pair's stiffness", "[timestep]") {
  // A 1.86 mm fragment (9 mg, its class stiffness 2.56e8 N/m) resting on a 28 mm
  // rock (30 g, 3.59e9 N/m, the crusher's) on a stiff floor, friction 10 (stuck),
  // the study's beta 0.11 with the average-mass dashpot. The fastest mode is the
  // fragment's stuck shear spring on the rock: inverse mass 3.5/m + 3.5/M, spring
  // the pair's (in series), dashpot on (m + M)/2. The audit once paired the rock's
  // rock-on-rock spring (1.8e9 N/m) with the fragment's mass, a contact that cannot
  // happen, and asked for a step 2.7 x shorter.
  const double rf = 0.928e-3, rr = 0.014, rho = 2650, beta = 0.11;
  const double kf = 2.5645e8, kr = 3.5933e9;
  sim::Model model;
  model.materials = {{"fragment", rho, kf, kf, 10.0, 0.0, 0.2},
                     {"rock", rho, kr, kr, 10.0, 0.0, 0.2},
                     {"floor", 7800.0, 1e13, 1e13, 10.0, 0.0, 0.2}};
  model.contact.damping_normal = model.contact.damping_shear = beta;
  model.contact.damping_mass = sim::DampingMass::Average;
  model.gravity = Vec3(0, 0, -9.81);
  sim::Wall floor = test::floorPlane();
  floor.material = 2;
  model.walls.push_back(floor);
  const double m = rho * 4.0 / 3.0 * std::numbers::pi * rf * rf * rf;
  const double big = rho * 4.0 / 3.0 * std::numbers::pi * rr * rr * rr;
  const double k = kf * kr / (kf + kr);
  const double c = 2 * beta * std::sqrt(0.5 * (m + big) * k);
  const double inv_t = 3.5 / m + 3.5 / big;
  // The audit counts the dashpot twice (kDashpotMultiplicity); the pair's exact
  // limit with one is what a single contact can take.
  const double single = sim::dampedStabilityLimit(k, c, inv_t);
  const double k_floor = kr * 1e13 / (kr + 1e13);
  const double rock_z = rr - (m + big) * 9.81 / k_floor, fragment_z = rock_z + rr + rf - m * 9.81 / k;
  const double nudge = 1e-5;  // m/s sideways: the stuck spring's force stays below friction
  std::vector<sim::SphereSpec> s{test::sphere({0, 0, rock_z}, rr), test::sphere({0, 0, fragment_z}, rf, {nudge, 0, 0})};
  s[0].material = 1;
  s[1].material = 0;
  const sim::World audited(model, s, 1);
  CHECK_THAT(audited.timestepAudit().damped_limit,
             WithinRel(sim::dampedStabilityLimit(k, sim::kDashpotMultiplicity * c, inv_t), 1e-12));
  CHECK_THAT(audited.dt(), WithinRel(sim::kDampedMargin * audited.timestepAudit().damped_limit, 1e-12));
  // The engine at just below and just above the single contact's limit: stable,
  // then growing (unchecked).
  model.timestep.allow_unsafe = true;
  model.watchdog.network_iterations = 0;
  model.watchdog.max_energy_growth = 0;
  model.watchdog.max_overlap_fraction = std::numeric_limits<double>::infinity();
  for (double f : {0.97, 1.03}) {
    INFO("dt = " << f << " x the single contact's limit " << single << " s");
    model.timestep.dt = f * single;
    sim::World w(model, s, 1);
    double fastest = 0;
    for (int n = 0; n < 20000; ++n) {
      w.step();
      const Vec3 v = w.particles().velocity[1];
      fastest = std::max(fastest, std::isfinite(v.norm()) ? v.norm() : std::numeric_limits<double>::infinity());
    }
    if (f < 1)
      CHECK(fastest <= 1.001 * nudge);
    else
      CHECK(fastest > 10 * nudge);
  }
}
