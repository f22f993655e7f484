// Normal impacts against closed forms: linear spring–dashpot restitution and
// duration (Eq 4-4), Hertz duration, ball–ball mass conventions.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "rocklab/sim/timestep.h"
#include "support.h"

using namespace rocklab;
using test::Vec3;

namespace {
struct Impact {
  double restitution;
  double duration;  // s
};

/// Two equal spheres approach head-on at +-v along x; runs until they part.
Impact twoSphereImpact(sim::Model model, double r, double v) {
  std::vector<sim::SphereSpec> s{test::sphere({-r - 1e-6, 0, 0}, r, {v, 0, 0}),
                                 test::sphere({r + 1e-6, 0, 0}, r, {-v, 0, 0})};
  sim::World w(model, s, 1);
  const auto& p = w.particles();
  double t_first = -1, t_last = -1;
  for (int k = 0; k < 2000000; ++k) {
    const bool touching = (p.position[1] - p.position[0]).norm() < 2 * r;
    const double t = w.time();
    w.step();
    if (touching && t_first < 0) t_first = t;
    if (touching) t_last = t;
    if (t_first >= 0 && !touching && t > t_last + 10 * w.dt()) break;
  }
  // Contact spans the steps whose force stage saw an overlap.
  const double v_after = p.velocity[1].x() - p.velocity[0].x();
  return {v_after / (2 * v), t_last - t_first + w.dt()};
}
}  // namespace

TEST_CASE("linear impact: restitution and duration within 1 %", "[impact]") {
  const double r = 0.01, v = 1.0, kn = 2e7;  // contact stiffness 1e7 N/m
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  for (double beta : {0.0, 0.11, 0.3}) {
    auto model = test::linearModel(kn, 0.0, beta);
    model.contact.damping_mass = sim::DampingMass::Reduced;
    model.timestep.dt = 1e-3 * sim::linearContactTime(m / 2, kn / 2, beta);
    const Impact i = twoSphereImpact(model, r, v);
    INFO("beta = " << beta);
    CHECK(i.restitution == Approx(sim::restitutionFromDamping(beta)).epsilon(0.01));
    CHECK(i.duration == Approx(sim::linearContactTime(m / 2, kn / 2, beta)).epsilon(0.01));
  }
}

TEST_CASE("study's average-mass dashpot: ball-ball damping is sqrt(2) stronger", "[impact]") {
  // Reference §6.2 [X]: with m = (m_A + m_B)/2 the two-body damping ratio is beta sqrt(2).
  const double r = 0.01, kn = 2e7, beta = 0.11;
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  auto model = test::linearModel(kn, 0.0, beta);
  model.contact.damping_mass = sim::DampingMass::Average;
  model.timestep.dt = 1e-3 * sim::linearContactTime(m / 2, kn / 2, beta);
  const Impact i = twoSphereImpact(model, r, 1.0);
  CHECK(i.restitution == Approx(sim::restitutionFromDamping(beta * std::sqrt(2.0))).epsilon(0.01));
  CHECK(i.restitution == Approx(0.61).margin(0.01));  // the reference's figure
}

TEST_CASE("ball-wall impact: restitution uses the ball mass", "[impact]") {
  const double r = 0.01, kn = 2e7, beta = 0.11, v = 1.5;
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  auto model = test::linearModel(kn, 0.0, beta);
  model.walls.push_back(test::floorPlane());
  model.timestep.dt = 1e-3 * sim::linearContactTime(m, kn / 2, beta);
  sim::World w(model, {test::sphere({0, 0, r + 1e-6}, r, {0, 0, -v})}, 1);
  for (int k = 0; k < 100000 && !(w.particles().velocity[0].z() > 0 && w.particles().position[0].z() > r + 1e-4); ++k)
    w.step();
  CHECK(w.particles().velocity[0].z() / v == Approx(sim::restitutionFromDamping(beta)).epsilon(0.01));
  CHECK(w.particles().velocity[0].z() / v == Approx(0.706).margin(0.002));  // reference §6.3
}

TEST_CASE("Hertz impact duration within 2 % of the Hertz formula", "[impact]") {
  const double r = 0.01, g = 1e9, nu = 0.25, v = 1.0;
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  auto model = test::linearModel();
  model.contact.law = sim::ContactLaw::HertzMindlin;
  for (auto& mat : model.materials) {
    mat.shear_modulus = g;
    mat.poisson = nu;
  }
  const double c = sim::hertzCoefficient(g, nu, r);  // R~ = R for equal spheres (Eq 2-24)
  const double expected = sim::hertzContactTime(m / 2, c, 2 * v);
  model.timestep.dt = expected / 2000;
  const Impact i = twoSphereImpact(model, r, v);
  CHECK(i.duration == Approx(expected).epsilon(0.02));
  CHECK(i.restitution == Approx(1.0).epsilon(1e-3));  // undamped, elastic
}
