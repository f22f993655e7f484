// Rigid clumps in the engine: torque-free tumbling, resting and colliding
// clumps, thread independence and restart.
#include <catch2/catch.hpp>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "rocklab/geometry/packing.h"
#include "rigid_body.h"
#include "rocklab/sim/output/checkpoint.h"
#include "support.h"

using namespace rocklab;
using test::Vec3;
using geometry::Quat;

namespace {

/// Planar four-ball clump of the study (rhombus of side r, experiments.md §c)
/// with the member masses summed (Eq 2-40..2-43); the body frame is principal.
sim::ClumpSpec fourBall(double r, double density, const Vec3& at) {
  const double s3 = std::sqrt(3.0);
  std::vector<Vec3> c = {{0, 0, 0}, {r, 0, 0}, {0.5 * r, 0.5 * s3 * r, 0}, {1.5 * r, 0.5 * s3 * r, 0}};
  Vec3 mean = Vec3::Zero();
  for (const Vec3& x : c) mean += x / 4.0;
  const double m = density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  geometry::Mat3 inertia = geometry::Mat3::Zero();
  for (Vec3& x : c) {
    x -= mean;
    inertia += m * (x.squaredNorm() * geometry::Mat3::Identity() - x * x.transpose()) +
               0.4 * m * r * r * geometry::Mat3::Identity();  // Eq 2-42, 2-43
  }
  Eigen::SelfAdjointEigenSolver<geometry::Mat3> eig(inertia);
  geometry::Mat3 axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(0) *= -1;
  sim::ClumpSpec spec;
  spec.position = at;
  spec.mass = 4 * m;
  spec.principal_inertia = eig.eigenvalues();
  for (const Vec3& x : c) spec.members.push_back({axes.transpose() * x, r});
  return spec;
}

/// A tumbling body: one member (its shape does not matter without contacts).
sim::ClumpSpec tumbler(const Vec3& inertia, const Vec3& omega) {
  sim::ClumpSpec spec;
  spec.mass = 1.0;
  spec.principal_inertia = inertia;
  spec.omega = omega;
  spec.members.push_back({Vec3::Zero(), 0.01});
  return spec;
}

/// Runs a torque-free body to t_end; returns its final orientation and the
/// largest relative rotational-energy error seen.
struct Tumble {
  Quat orientation;
  double max_energy_error = 0.0;
  double min_body_omega_y = 1e300;
};
Tumble tumble(double dt, double t_end) {
  auto model = test::linearModel(1.0);  // soft: nothing touches, dt is free
  model.timestep.dt = dt;
  model.watchdog.max_energy_growth = 0.0;
  sim::World w(model, {}, {tumbler(Vec3(1, 2, 3), Vec3(0.01, 1.0, 0.02))}, 1);
  double e0 = 0.0;
  Tumble out;
  const auto steps = static_cast<int>(std::lround(t_end / dt));
  for (int k = 0; k < steps; ++k) {
    w.step([&](const sim::Snapshot& s) {
      const double e = s.energy.kinetic_rotational;
      if (k == 0) e0 = e;
      out.max_energy_error = std::max(out.max_energy_error, std::abs(e - e0) / e0);
      const Vec3 body_w = s.clump_orientation[0].conjugate() * s.clump_omega[0];
      out.min_body_omega_y = std::min(out.min_body_omega_y, body_w.y());
    });
  }
  out.orientation = w.particles().clumps.orientation[0];
  return out;
}

double angleBetween(const Quat& a, const Quat& b) { return a.angularDistance(b); }

}  // namespace

TEST_CASE("clump: torque-free tumbling conserves energy and flips about the middle axis", "[clump]") {
  // Spin near the intermediate axis of an asymmetric body is unstable (the
  // "tennis racket" flip): the body-frame spin about y reverses. A sphere-only
  // integrator (no gyroscopic term) would never flip.
  const Tumble t = tumble(1e-3, 30.0);
  CHECK(t.max_energy_error < 1e-5);
  CHECK(t.min_body_omega_y < -0.9);
}

TEST_CASE("clump: the rotation's sine and cosine equal libm's to round-off on both sides of its series' bounds",
          "[clump]") {
  // sim/src/rigid_body.h sinCos: series below 1e-3 and 0.1 rad, libm above.
  double worst = 0.0;
  for (double x = 1e-9; x < 0.3; x *= 1.01)
    for (const double sx : {x, -x}) {
      double s = 0.0, c = 0.0;
      sim::detail::sinCos(sx, s, c);
      worst = std::max({worst, std::abs(s - std::sin(sx)) / std::abs(std::sin(sx)), std::abs(c - std::cos(sx))});
    }
  CHECK(worst < 4e-16);  // two units in the last place
}

TEST_CASE("clump: a step's free rotation matches the same splitting written with quaternion products",
          "[clump]") {
  // The integrator writes each sub-rotation out (q times a one-axis quaternion,
  // the momentum turned by the double-angle formulas); here the splitting of
  // rigid_body.h is done the plain way, with libm and Eigen's products.
  const Vec3 inertia(1.0, 2.0, 3.0), L(0.3, -1.2, 2.5);
  Quat q(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const double dt = 1e-3;
  Quat reference = q;
  Vec3 pi = q.conjugate() * L;
  for (const auto& [axis, tau] : std::vector<std::pair<int, double>>{{0, dt / 2}, {1, dt / 2}, {2, dt}, {1, dt / 2}, {0, dt / 2}}) {
    const double angle = tau * pi[axis] / inertia[axis];
    Vec3 v = Vec3::Zero();
    v[axis] = std::sin(0.5 * angle);
    reference = reference * Quat(std::cos(0.5 * angle), v.x(), v.y(), v.z());
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const double pa = pi[a], pb = pi[b];
    pi[a] = std::cos(angle) * pa + std::sin(angle) * pb;
    pi[b] = -std::sin(angle) * pa + std::cos(angle) * pb;
  }
  reference.normalize();
  sim::detail::rotateFree(q, inertia, L, dt);
  CHECK(q.coeffs().isApprox(reference.coeffs(), 1e-15));
  CHECK(q.angularDistance(reference) < 1e-15);
}

TEST_CASE("clump: bodies rotated in a batch end bitwise where each rotated alone ends", "[clump]") {
  // integrateClumps turns four bodies at once (their chains interleaved); each body's
  // arithmetic must stay its own, in every branch of sinCos (half angles below 1e-3,
  // up to 0.1 and above), or results would depend on the clumps' count and order.
  const Vec3 inertia[4] = {{1.0, 2.0, 3.0}, {2e-6, 2e-6, 3e-6}, {0.5, 0.4, 0.3}, {1e-3, 2e-3, 1.5e-3}};
  const Vec3 L[4] = {{0.3, -1.2, 2.5}, {1e-4, 3e-5, -2e-4}, {-40.0, 25.0, 60.0}, {1e-9, 0.0, -2e-9}};
  Quat batch[4], alone[4];
  for (int l = 0; l < 4; ++l) batch[l] = alone[l] = Quat(Eigen::AngleAxisd(0.3 + l, Vec3(1, 2 - l, 3).normalized()));
  for (const double dt : {1e-6, 1e-3, 1e-2})
    for (int step = 0; step < 3; ++step) {
      sim::detail::rotateFreeBatch<4>(batch, inertia, L, dt);
      for (int l = 0; l < 4; ++l) sim::detail::rotateFree(alone[l], inertia[l], L[l], dt);
    }
  for (int l = 0; l < 4; ++l) {
    INFO("body " << l);
    CHECK(batch[l].coeffs() == alone[l].coeffs());
  }
  CHECK(batch[0].angularDistance(Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()))) > 1e-3);  // they turned
}

TEST_CASE("clump: the rotation integrator converges at second order", "[clump]") {
  const Quat reference = tumble(1.25e-4, 10.0).orientation;
  const double coarse = angleBetween(tumble(1e-3, 10.0).orientation, reference);
  const double fine = angleBetween(tumble(5e-4, 10.0).orientation, reference);
  INFO("orientation error dt=1e-3: " << coarse << " rad, dt=5e-4: " << fine << " rad");
  CHECK(coarse / fine > 3.0);  // 4 for second order, less the reference's own error
  CHECK(coarse < 1e-5);
}

TEST_CASE("clump: members never push each other apart", "[clump]") {
  // The four members overlap by half a diameter; without the pair exclusion the
  // clump would be pushed apart or spun up at the first step.
  auto model = test::linearModel(1e9);
  model.timestep.dt = 9e-7;
  sim::World w(model, {}, {fourBall(0.00735, 2730, Vec3::Zero())}, 1);
  for (int k = 0; k < 100; ++k) w.step();
  CHECK(w.particles().clumps.velocity[0].norm() == 0.0);
  CHECK(w.particles().clumps.angular_momentum[0].norm() == 0.0);
  CHECK(w.stats().pairs_in_list == 0);
}

TEST_CASE("clump: a colliding pair conserves linear and angular momentum", "[clump]") {
  auto model = test::linearModel(1e6, 0.5, 0.0);
  auto a = fourBall(0.00735, 2730, Vec3(0, 0, 0));
  auto b = fourBall(0.00735, 2730, Vec3(0.03, 0.004, 0.002));
  b.orientation = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  a.velocity = Vec3(0.5, 0, 0);
  b.omega = Vec3(0, 0, 3.0);
  sim::World w(model, {}, {a, b}, 1);
  auto momenta = [&w](Vec3& p, Vec3& l) {
    const auto& k = w.particles().clumps;
    p.setZero();
    l.setZero();
    for (std::size_t c = 0; c < k.size(); ++c) {
      p += k.mass[c] * k.velocity[c];
      l += k.mass[c] * k.position[c].cross(k.velocity[c]) + k.angular_momentum[c];
    }
  };
  Vec3 p0, l0, p1, l1;
  momenta(p0, l0);
  std::size_t touching_steps = 0;
  for (int k = 0; k < 40000; ++k)
    w.step([&](const sim::Snapshot& s) { touching_steps += s.contacts; });
  momenta(p1, l1);
  REQUIRE(touching_steps > 0);  // they really met
  CHECK((p1 - p0).norm() < 1e-12 * p0.norm());
  // Positions and half-step velocities are staggered, so L is conserved to O(dt).
  CHECK((l1 - l0).norm() < 1e-3 * l0.norm());
}

TEST_CASE("clump: a four-ball clump dropped on a floor comes to rest lying flat", "[clump]") {
  auto model = test::linearModel(1e6, 0.4, 0.3);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls.push_back(test::floorPlane());
  const double r = 0.00735;
  auto c = fourBall(r, 2730, Vec3(0, 0, 0.05));
  c.orientation = Quat(Eigen::AngleAxisd(0.4, Vec3(1, 1, 0).normalized()));
  sim::World w(model, {}, {c}, 1);
  while (w.time() < 1.5) w.step();
  const auto& k = w.particles().clumps;
  CHECK(k.velocity[0].norm() < 1e-3);
  // Lying flat, the centre of mass is one member radius above the floor (less a
  // static overlap m g / (4 k) of 5e-8 m), and the plane normal (the axis of the
  // largest principal moment, body z) is vertical.
  CHECK(k.position[0].z() == Approx(r).margin(2e-4));
  const Vec3 normal = k.orientation[0] * Vec3::UnitZ();
  CHECK(std::abs(normal.z()) > 0.999);
}

TEST_CASE("clump: bitwise identical on 1 and 2 threads and across a restart", "[clump][determinism]") {
  auto model = test::linearModel(2e7, 0.4, 0.1);
  model.gravity = Vec3(1.0, 0, -9.81);
  model.walls.push_back(test::floorPlane());
  std::vector<sim::ClumpSpec> clumps;
  geometry::Rng rng(5);
  // 1400 clumps = 5600 member balls: enough for a two-thread team.
  for (const Vec3& x : geometry::latticePoints(geometry::LatticeKind::SimpleCubic, 0.031, Vec3(0.5, 0.5, 0.5),
                                               Vec3::Zero(), {20, 10, 7})) {
    auto c = fourBall(0.00735, 2730, x);
    c.orientation = Quat(Eigen::AngleAxisd(6.28 * rng.uniform(), Vec3(rng.uniform(), rng.uniform(), 1).normalized()));
    clumps.push_back(c);
  }
  std::uint64_t hash[2];
  for (int t : {1, 2}) {
    sim::World w(model, {}, clumps, t);
    w.setTeamPolicy(sim::TeamPolicy::Full);  // no timed switch to one thread
    REQUIRE(w.threads() == t);
    for (int k = 0; k < 400; ++k) w.step();
    hash[t - 1] = w.stateHash();
  }
  CHECK(hash[0] == hash[1]);

  sim::World first(model, {}, clumps, 1);
  for (int k = 0; k < 150; ++k) first.step();
  const auto path = std::filesystem::temp_directory_path() / "rocklab-clump-restart.h5";
  sim::output::writeCheckpoint(path, first.exportState(), "scene");
  auto cp = sim::output::readCheckpoint(path);
  std::filesystem::remove(path);
  REQUIRE(cp.state.particles.clumps.size() == clumps.size());
  sim::World second(model, std::move(cp.state), 1);
  while (second.stepCount() < 400) second.step();
  CHECK(second.stateHash() == hash[0]);
}

TEST_CASE("clump: removing a member removes its clump and keeps the rest running", "[clump]") {
  auto model = test::linearModel(1e6, 0.4, 0.1);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls.push_back(test::floorPlane());
  std::vector<sim::SphereSpec> spheres = {test::sphere(Vec3(0.1, 0, 0.01), 0.01),
                                          test::sphere(Vec3(0.1, 0, 0.0301), 0.01)};
  std::vector<sim::ClumpSpec> clumps = {fourBall(0.00735, 2730, Vec3(0, 0, 0.0074)),
                                        fourBall(0.00735, 2730, Vec3(0, 0.04, 0.0074))};
  sim::World w(model, spheres, clumps, 1);
  for (int k = 0; k < 2000; ++k) w.step();
  sim::WorldState s = w.exportState();
  REQUIRE(s.particles.size() == 10);
  std::vector<bool> remove(10, false);
  remove[0] = true;  // the lower free sphere
  remove[3] = true;  // the second member of the first clump
  const sim::WorldState cut = sim::withoutBalls(s, remove);
  const auto& p = cut.particles;
  REQUIRE(p.size() == 5);  // one free sphere and one whole clump
  CHECK(p.id[0] == 1);
  CHECK(p.clumps.size() == 1);
  CHECK(p.clumps.id[0] == s.particles.clumps.id[1]);
  CHECK(p.clumps.member_ball == std::vector<std::uint32_t>{1, 2, 3, 4});
  CHECK(p.clump == std::vector<std::int32_t>{-1, 0, 0, 0, 0});
  for (const auto& h : cut.pair_history) CHECK((h.i < 5 && h.j < 5 && h.i < h.j));
  for (const auto& h : cut.wall_history) CHECK(h.particle < 5);
  sim::World rest(model, cut, 1);
  const Vec3 before = rest.particles().clumps.position[0];
  while (rest.time() < w.time() + 0.5) rest.step();
  // The upper sphere falls onto the floor; the remaining clump stays where it lay.
  CHECK(rest.particles().position[0].z() == Approx(0.01).margin(1e-4));
  CHECK((rest.particles().clumps.position[0] - before).norm() < 1e-4);
}
