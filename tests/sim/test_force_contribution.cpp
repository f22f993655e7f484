// The force-contribution seam (sim/force_contribution.h), proven by a test-only
// contribution: linear springs between pairs of balls. Two balls on one spring
// oscillate with the analytic frequency; the energy it stores is in the energy
// balance; results are bitwise the same on one and two threads; a spring too
// stiff for the step is stopped by the contact-network check.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "rocklab/sim/force_contribution.h"
#include "sim/support.h"

using namespace rocklab;
using geometry::Vec3;

namespace {

/// Linear springs of stiffness k (N/m) and rest length L0 between ball pairs,
/// acting along the line of centres.
class TestSprings : public sim::ForceContribution {
 public:
  struct Link {
    std::uint32_t a, b;
    double rest;  // m
  };
  TestSprings(std::vector<Link> links, double k) : links_(std::move(links)), k_(k) {}
  std::string name() const override { return "test springs"; }
  void addForces(const sim::ForceInput& in, std::span<Vec3> force, std::span<Vec3> /*torque*/) override {
    for (const Link& l : links_) {
      const Vec3 d = in.particles.position[l.b] - in.particles.position[l.a];
      const double len = d.norm();
      const Vec3 f = k_ * (len - l.rest) * (d / len);  // pulls a towards b when stretched
      force[l.a] += f;
      force[l.b] -= f;
    }
  }
  double potentialEnergy(const sim::ForceInput& in) const override {
    double e = 0;
    for (const Link& l : links_) {
      const double s = (in.particles.position[l.b] - in.particles.position[l.a]).norm() - l.rest;
      e += 0.5 * k_ * s * s;
    }
    return e;
  }
  void networkSprings(const sim::ForceInput& in, std::vector<sim::NetworkSpring>& out) const override {
    for (const Link& l : links_) {
      const Vec3 xa = in.particles.position[l.a], xb = in.particles.position[l.b];
      sim::NetworkSpring s;
      s.a = l.a;
      s.b = l.b;
      s.normal = (xb - xa).normalized();
      s.point = 0.5 * (xa + xb);
      s.kn = k_;
      out.push_back(s);
    }
  }

 private:
  std::vector<Link> links_;
  double k_;
};

}  // namespace

TEST_CASE("force contribution: two balls on a spring oscillate at omega = sqrt(2k/m)", "[contribution]") {
  const double r = 0.005, rest = 0.05, stretch = 0.002, k = 1e3;
  sim::Model model = test::linearModel(1e6);
  sim::World w(model, {test::sphere(Vec3(0, 0, 0), r), test::sphere(Vec3(rest + stretch, 0, 0), r)}, 1);
  w.addForceContribution(std::make_shared<TestSprings>(std::vector<TestSprings::Link>{{0, 1, rest}}, k));
  const double m = 2730.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double omega = std::sqrt(2.0 * k / m);  // reduced mass m/2
  const double period = 2.0 * std::numbers::pi / omega;
  INFO("dt " << w.dt() << " s, omega dt " << omega * w.dt());
  REQUIRE(omega * w.dt() < 0.05);
  double e_first = 0, e_lo = 1e300, e_hi = -1e300, worst = 0;
  const auto steps = static_cast<std::uint64_t>(std::llround(1.25 * period / w.dt()));
  for (std::uint64_t s = 0; s < steps; ++s) {
    w.step([&](const sim::Snapshot& snap) {
      const double sep = (snap.position[1] - snap.position[0]).norm() - rest;
      worst = std::max(worst, std::abs(sep - stretch * std::cos(omega * snap.time)));
      const double e = snap.energy.total();
      if (snap.step == 0) e_first = e;
      e_lo = std::min(e_lo, e);
      e_hi = std::max(e_hi, e);
      CHECK(snap.energy.potential_other >= 0);
    });
  }
  const double e0 = 0.5 * k * stretch * stretch;
  CHECK(e_first == Approx(e0).epsilon(1e-12));
  // Leapfrog: phase error ~ (omega dt)^2 / 24 per radian, energy error ~ (omega dt)^2 / 8.
  CHECK(worst < 1e-3 * stretch);
  CHECK((e_hi - e_lo) / e0 < 0.5 * std::pow(omega * w.dt(), 2));
  // The spring's energy moves into motion and back: at a quarter period it is kinetic.
  CHECK(e_hi - e_lo > 0);
}

TEST_CASE("force contribution: the extra-forces stage is bitwise the same on one and two threads", "[contribution]") {
  // 6000 balls (two threads need >= 2000), touching a floor and each other in rows, with
  // springs between neighbours of a row: contacts and contributions on the same balls.
  const double r = 0.001;
  sim::Model model = test::linearModel(1e5, 0.3, 0.1);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls = {test::floorPlane(0.0)};
  std::vector<sim::SphereSpec> balls;
  std::vector<TestSprings::Link> links;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 100; ++x) {
      if (x > 0) links.push_back({static_cast<std::uint32_t>(balls.size() - 1),
                                  static_cast<std::uint32_t>(balls.size()), 2.2 * r});
      balls.push_back(test::sphere(Vec3(1.99 * r * x, 3.0 * r * y, 0.99 * r + 1e-4 * r * (x % 3)), r));
    }
  auto run = [&](int threads, bool springs) {
    sim::World w(model, balls, threads);
    w.setTeamPolicy(sim::TeamPolicy::Full);  // no timed switch to one thread
    if (springs) w.addForceContribution(std::make_shared<TestSprings>(links, 200.0));
    for (int s = 0; s < 300; ++s) w.step(s % 50 == 0 ? [](const sim::Snapshot&) {} : std::function<void(const sim::Snapshot&)>{});
    return std::pair{w.stateHash(), w.threads()};
  };
  const auto [one, t1] = run(1, true);
  const auto [two, t2] = run(2, true);
  REQUIRE(t1 == 1);
  if (t2 < 2) WARN("this machine gives the world one thread only; the two-thread half is not exercised");
  CHECK(one == two);
  CHECK(run(1, false).first != one);  // the springs did act
}

TEST_CASE("force contribution: a spring too stiff for the step is stopped by the network check", "[contribution]") {
  const double r = 0.005, rest = 0.05;
  sim::Model model = test::linearModel(1e6);
  model.watchdog.network_interval = 1;
  sim::World w(model, {test::sphere(Vec3(0, 0, 0), r), test::sphere(Vec3(rest, 0, 0), r)}, 1);
  const double m = 2730.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  // omega dt = 3 > 2: the leapfrog cannot take this spring.
  const double k = 0.5 * m * std::pow(3.0 / w.dt(), 2);
  w.addForceContribution(std::make_shared<TestSprings>(std::vector<TestSprings::Link>{{0, 1, rest}}, k));
  try {
    for (int s = 0; s < 10; ++s) w.step();
    FAIL("the stiff spring was not stopped");
  } catch (const sim::WatchdogError& e) {
    CHECK_THAT(e.what(), Catch::Contains("unstable for the contact network"));
  }
  CHECK(w.stats().network_step_ratio > 1.0);
}
