// Integration checks with exact answers: free flight, rolling and slipping on a
// slope, energy conservation without damping, second-order convergence.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "rocklab/geometry/packing.h"
#include "support.h"

using namespace rocklab;
using test::Vec3;

TEST_CASE("free flight is exact to round-off", "[motion]") {
  auto model = test::linearModel();
  model.gravity = Vec3(0.3, -0.2, -9.81);
  model.timestep.dt = 3.2e-5;
  const Vec3 x0(0.1, 0.2, 5.0), v0(1.5, -0.5, 3.0);
  sim::World w(model, {test::sphere(x0, 0.01, v0)}, 1);
  for (int k = 0; k < 31250; ++k) w.step();  // 1 s
  const double t = w.time();
  const Vec3 exact = x0 + v0 * t + 0.5 * model.gravity * t * t;
  CHECK((w.particles().position[0] - exact).norm() < 1e-12 * exact.norm());
  // The stored velocity is the half-step one, v(t - dt/2).
  const Vec3 v_half = v0 + model.gravity * (t - 0.5 * w.dt());
  CHECK((w.particles().velocity[0] - v_half).norm() < 1e-12 * v_half.norm());
}

namespace {
/// A sphere resting on a plane z = 0 under gravity tilted by theta about y.
/// Returns (down-slope acceleration m/s^2, spin acceleration rad/s^2) measured
/// between t1 and t2 from synchronised snapshots.
std::pair<double, double> slope(double theta_deg, double mu) {
  const double r = 0.01, kn = 2e8, g = 9.81, theta = theta_deg * std::numbers::pi / 180;
  auto model = test::linearModel(kn, mu, 0.3);
  model.gravity = g * Vec3(std::sin(theta), 0, -std::cos(theta));
  model.walls.push_back(test::floorPlane());
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double sag = m * g * std::cos(theta) / (kn / 2);  // static overlap
  sim::World w(model, {test::sphere({0, 0, r - sag}, r)}, 1);
  const auto n1 = static_cast<std::uint64_t>(0.05 / w.dt()), n2 = static_cast<std::uint64_t>(0.25 / w.dt());
  double t1 = 0, t2 = 0, v1 = 0, v2 = 0, w1 = 0, w2 = 0;
  while (w.stepCount() <= n2) {
    const auto k = w.stepCount();
    if (k == n1 || k == n2)
      w.step([&](const sim::Snapshot& s) {
        (k == n1 ? t1 : t2) = s.time;
        (k == n1 ? v1 : v2) = s.velocity[0].x();
        (k == n1 ? w1 : w2) = s.omega[0].y();
      });
    else
      w.step();
  }
  return {(v2 - v1) / (t2 - t1), (w2 - w1) / (t2 - t1)};
}
}  // namespace

TEST_CASE("sphere on a slope rolls without slipping below tan(theta) = 7 mu / 2", "[motion]") {
  const double g = 9.81, theta = 20.0, mu = 0.5;  // tan 20 deg = 0.36 < 1.75
  const auto [a, alpha] = slope(theta, mu);
  const double expected = 5.0 / 7.0 * g * std::sin(theta * std::numbers::pi / 180);
  CHECK(a == Approx(expected).epsilon(0.01));
  CHECK(alpha * 0.01 == Approx(expected).epsilon(0.01));  // rolling: alpha R = a
}

TEST_CASE("sphere on a steep slope slips: g (sin - mu cos) and the analytic spin-up", "[motion]") {
  const double g = 9.81, theta = 40.0, mu = 0.2, r = 0.01;  // tan 40 deg = 0.84 > 0.7
  const double th = theta * std::numbers::pi / 180;
  const auto [a, alpha] = slope(theta, mu);
  CHECK(a == Approx(g * (std::sin(th) - mu * std::cos(th))).epsilon(0.01));
  // Friction mu m g cos(theta) at lever r on I = 2/5 m r^2.
  CHECK(alpha == Approx(2.5 * mu * g * std::cos(th) / r).epsilon(0.01));
}

namespace {
/// Mean total energy over the first and the last tenth of the observations.
std::pair<double, double> energyDrift(sim::World& w, int steps, int every) {
  std::vector<double> energy;
  for (int k = 0; k < steps; ++k) {
    if (k % every == 0)
      w.step([&](const sim::Snapshot& snap) { energy.push_back(snap.energy.total()); });
    else
      w.step();
  }
  // Window means remove the bounded leapfrog oscillation inside contacts.
  auto mean = [&](std::size_t a, std::size_t b) {
    double sum = 0;
    for (std::size_t k = a; k < b; ++k) sum += energy[k];
    return sum / static_cast<double>(b - a);
  };
  const std::size_t n = energy.size();
  return {mean(0, n / 10), mean(n - n / 10, n)};
}

/// Frictionless, undamped model with a floor at z = 0 and four side planes at +-half.
sim::Model conservativeBox(double half) {
  auto model = test::linearModel(1e6, 0.0, 0.0);
  model.gravity = Vec3(0, 0, -9.81);
  sim::Wall floor = test::floorPlane();
  model.walls.push_back(floor);
  for (int axis = 0; axis < 2; ++axis)
    for (double side : {-1.0, 1.0}) {
      sim::Wall w = floor;
      w.point = Vec3::Zero();
      w.point[axis] = half * side;
      w.normal = Vec3::Zero();
      w.normal[axis] = -side;
      model.walls.push_back(w);
    }
  return model;
}
}  // namespace

TEST_CASE("undamped frictionless columns: energy drift below 1e-4 over 1e5 steps", "[motion]") {
  // 25 columns of 6 balls resting on the floor and on each other, started near
  // static equilibrium with small random velocities so that no contact opens:
  // leapfrog is symplectic here and the energy must not drift at the default
  // safety factor.
  auto model = conservativeBox(0.2);
  const double r = 0.01, k = 5e5, g = 9.81;  // contact stiffness: 1e6 and 1e6 in series
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const int layers = 6;
  std::vector<sim::SphereSpec> s;
  geometry::Rng rng(4);
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      double z = r - layers * m * g / k;  // the floor carries the whole column
      for (int layer = 0; layer < layers; ++layer) {
        const Vec3 v = 1e-5 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
        s.push_back(test::sphere({-0.05 + 0.0201 * i, -0.05 + 0.0201 * j, z}, r, {0, 0, v.z()}));
        z += 2 * r - (layers - layer - 1) * m * g / k;  // contact above carries the rest
      }
    }
  sim::World w(model, s, 1);
  const auto [e0, e1] = energyDrift(w, 100000, 100);
  INFO("E start " << e0 << " J, E end " << e1 << " J");
  CHECK(std::abs(e1 - e0) / std::abs(e0) < 1e-4);
}

TEST_CASE("undamped frictionless bouncing balls: energy drift below 1e-3 over 1e5 steps", "[motion]") {
  // Each impact starts between two steps, where the force has a kink and leapfrog
  // is not symplectic. Measured drift: 2.5e-3 at safety factor 0.5, 2.1e-4 at 0.1.
  auto model = conservativeBox(0.1);
  model.timestep.safety_factor = 0.1;
  std::vector<sim::SphereSpec> s;
  for (int k = 0; k < 12; ++k)
    s.push_back(test::sphere({-0.07 + 0.012 * k, 0.01 * (k % 3), 0.02 + 0.025 * (k % 4)}, 0.005,
                             {0.3 * std::sin(k), 0.2 * std::cos(k), 0.1 * k}));
  sim::World w(model, s, 1);
  const auto [e0, e1] = energyDrift(w, 100000, 100);
  INFO("E start " << e0 << " J, E end " << e1 << " J");
  CHECK(std::abs(e1 - e0) / std::abs(e0) < 1e-3);
}

TEST_CASE("leapfrog converges at second order inside a contact", "[motion]") {
  // A ball meets a wall at v0 with no gravity: overlap(t) = (v0 / w) sin(w t).
  const double r = 0.01, kn = 2e6, v0 = 0.5;
  const double m = 2730 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double omega = std::sqrt(kn / 2 / m);
  const double t_end = 0.3 * std::numbers::pi / omega;
  std::vector<double> errors;
  for (int refine : {1, 2, 4, 8}) {
    auto model = test::linearModel(kn);
    model.walls.push_back(test::floorPlane());
    const int steps = 200 * refine;
    model.timestep.dt = t_end / steps;
    sim::World w(model, {test::sphere({0, 0, r}, r, {0, 0, -v0})}, 1);
    for (int k = 0; k < steps; ++k) w.step();
    const double exact = r - v0 / omega * std::sin(omega * w.time());
    errors.push_back(std::abs(w.particles().position[0].z() - exact));
  }
  for (std::size_t k = 0; k + 1 < errors.size(); ++k) {
    const double order = std::log2(errors[k] / errors[k + 1]);
    INFO("errors " << errors[k] << " -> " << errors[k + 1]);
    CHECK(order == Approx(2.0).margin(0.15));
  }
}

TEST_CASE("Cundall local damping: a thrown ball rises at g (1 + alpha) and falls at g (1 - alpha)", "[motion]") {
  // Eq 2-15, sign form: the force on a free ball is its weight, |F| = m g, so the
  // damping term -alpha |F| sign(v) makes the deceleration (1 + alpha) g while it
  // rises and the acceleration (1 - alpha) g while it falls; a component with no
  // force (x) and a spin with no torque are left alone.
  const double alpha = 0.3, g = 9.81, v0 = 1.0, dt = 3.2e-5;
  auto model = test::linearModel();
  model.gravity = Vec3(0, 0, -g);
  model.contact.local_damping = alpha;
  model.timestep.dt = dt;
  auto s = test::sphere({0, 0, 1.0}, 0.01, {0.5, 0, v0});
  s.omega = Vec3(3, -2, 1);
  sim::World w(model, {s}, 1);
  const double t_up = v0 / ((1 + alpha) * g), z_peak = 1.0 + v0 * v0 / (2 * (1 + alpha) * g);
  while (w.time() < t_up + 0.3) w.step();
  const double tf = w.time() - t_up;
  // The sign of v flips inside one step, which may carry the rising damping:
  // at most 2 alpha g dt of velocity, 2 alpha g dt tf of position (+ O(dt^2)).
  // Undamped the ball would be 0.13 m lower here; with alpha on the rise only, 0.13 m higher.
  const double dv = 2 * alpha * g * dt, dz = dv * tf + g * dt * dt;
  const auto& p = w.particles();
  CHECK(std::abs(p.position[0].z() - (z_peak - 0.5 * (1 - alpha) * g * tf * tf)) < dz);
  // The stored velocity is the half-step one.
  CHECK(std::abs(p.velocity[0].z() + (1 - alpha) * g * (tf - 0.5 * dt)) < dv);
  CHECK(p.velocity[0].x() == 0.5);
  CHECK(p.omega[0] == Vec3(3, -2, 1));
  // Falling: every step adds exactly (1 - alpha) g dt (round-off only).
  const double v_before = p.velocity[0].z();
  w.step();
  CHECK(w.particles().velocity[0].z() - v_before == Approx(-(1 - alpha) * g * dt).epsilon(1e-9));
}

TEST_CASE("gravity schedule: gravity turns at the scheduled times and the ball follows the pieces", "[motion]") {
  // Free flight under g0; at t1 a sideways 2 m/s^2 is added; at t2 gravity is
  // switched off: x is 0 before t1, (a/2)(t - t1)^2 between, then a straight line.
  const double a = 2.0, g = 9.81, t1 = 0.1, t2 = 0.2, dt = 3.2e-5;
  auto model = test::linearModel();
  model.gravity = Vec3(0, 0, -g);
  model.gravity_changes = {{t1, Vec3(a, 0, -g)}, {t2, Vec3::Zero()}};
  model.timestep.dt = dt;
  sim::World w(model, {test::sphere({0, 0, 5.0}, 0.01)}, 1);
  while (w.time() < t1 - 0.5 * dt) w.step();
  CHECK(w.particles().position[0].x() == 0.0);
  CHECK(w.gravity() == Vec3(0, 0, -g));
  while (w.time() < 0.15) w.step();
  CHECK(w.gravity() == Vec3(a, 0, -g));
  // The switch is taken at the first step at or after its time: off by at most
  // one step, a velocity error a dt and a position error a dt (t - t1) at most.
  double t = w.time();
  CHECK(std::abs(w.particles().position[0].x() - 0.5 * a * (t - t1) * (t - t1)) < a * dt * (t - t1) + 1e-12);
  while (w.time() < 0.3) w.step();
  CHECK(w.gravity() == Vec3::Zero());
  t = w.time();
  const double x_exact = 0.5 * a * (t2 - t1) * (t2 - t1) + a * (t2 - t1) * (t - t2);
  CHECK(std::abs(w.particles().position[0].x() - x_exact) < 2 * a * dt * (t - t1) + 1e-12);
  // Vertically: g until t2, then coasting at the speed reached.
  const double z_exact = 5.0 - 0.5 * g * t2 * t2 - g * t2 * (t - t2);
  CHECK(std::abs(w.particles().position[0].z() - z_exact) < 2 * g * dt * t);
  CHECK(std::abs(w.particles().velocity[0].z() + g * t2) < g * dt);
}
