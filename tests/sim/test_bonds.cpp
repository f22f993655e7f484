// Parallel bonds (sim/bonds.h, dem-models.md §8.2). The prescribed-motion
// cases give the two balls an enormous mass, so the bond cannot change their
// motion and every step adds exactly V dt (and Omega dt) to the bond: its force
// and moment after N steps are then known in closed form (Eq 2-29..2-32), and
// so is the step at which it must break (Eq 2-33, 2-34).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <numbers>

#include <unistd.h>

#include "rocklab/sim/output/checkpoint.h"
#include "rocklab/sim/output/run_file.h"
#include "sim/support.h"

using namespace rocklab;
using geometry::Vec3;

namespace {

constexpr double kRadius = 0.0025;  // m, the study's ball radius (Table 5.2)
constexpr double kBondKn = 5e12;    // Pa/m (Table 5.2)
constexpr double kBondKs = 2e12;    // Pa/m

/// Linear contacts, no gravity, the study's bond stiffnesses; `density` of the balls.
sim::Model bondModel(double density = 2700.0) {
  sim::Model m = test::linearModel(1e6);
  m.materials[0].density = density;
  m.bonds.normal_stiffness = kBondKn;
  m.bonds.shear_stiffness = kBondKs;
  return m;
}

sim::BondSpec bond(std::uint32_t a, std::uint32_t b, double tensile = INFINITY,
                   double shear = INFINITY) {
  return sim::BondSpec{a, b, tensile, shear};
}

/// Two touching balls along x, the second with the given velocity and both
/// spinning oppositely at +-spin/2, so the bond sees V and Omega = spin.
struct Prescribed {
  Vec3 velocity = Vec3::Zero();  // m/s of ball 1
  Vec3 spin = Vec3::Zero();      // rad/s, omega_1 - omega_0
};

sim::World prescribedPair(const Prescribed& motion, sim::BondSpec spec, double dt,
                          sim::BondFailureRule rule = sim::BondFailureRule::Stress) {
  sim::Model model = bondModel(1e30);  // immovable by the bond
  model.timestep.dt = dt;
  model.bonds.failure_rule = rule;
  auto a = test::sphere(Vec3(0, 0, 0), kRadius);
  auto b = test::sphere(Vec3(2 * kRadius, 0, 0), kRadius, motion.velocity);
  a.omega = -0.5 * motion.spin;
  b.omega = 0.5 * motion.spin;
  return sim::World(model, {a, b}, {}, {spec}, 1);
}

const sim::BondDisc kDisc = sim::bondDisc(kRadius);  // phi = 1, equal balls

}  // namespace

TEST_CASE("bond: disc and peak stresses (Eq 2-35..2-38, 2-33, 2-34)", "[bonds]") {
  const sim::BondDisc d = sim::bondDisc(0.002);
  CHECK(d.area == Approx(std::numbers::pi * 4e-6));
  CHECK(d.polar == Approx(0.5 * std::numbers::pi * 16e-12));
  CHECK(d.inertia == Approx(0.25 * std::numbers::pi * 16e-12));
  // Tension -F_n / A plus bending |M_s| R / I; shear |F_s| / A plus twist |M_n| R / J.
  const sim::BondStress s = sim::bondStress(d, -10.0, Vec3(0, 3, 4), -0.01, Vec3(0, 0.002, 0));
  CHECK(s.tensile == Approx(10.0 / d.area + 0.002 * 0.002 / d.inertia));
  CHECK(s.shear == Approx(5.0 / d.area + 0.01 * 0.002 / d.polar));
  // Compression lowers the tensile stress.
  CHECK(sim::bondStress(d, 10.0, Vec3::Zero(), 0.0, Vec3::Zero()).tensile < 0);
}

TEST_CASE("bond: prescribed tension, shear, bending and twist give the analytic force and moment",
          "[bonds]") {
  const double dt = 1e-7, v = 0.01, w = 2.0;  // s, m/s, rad/s
  const int steps = 100;
  SECTION("tension: F_n = -k_n A U_n (Eq 2-29)") {
    sim::World world = prescribedPair({Vec3(v, 0, 0), Vec3::Zero()}, bond(0, 1), dt);
    for (int s = 0; s < steps; ++s) world.step();
    const sim::BondState& b = world.bonds();
    const double stretch =
        (world.particles().position[1] - world.particles().position[0]).norm() - 2 * kRadius;
    CHECK(stretch == Approx(steps * v * dt).epsilon(1e-9));
    CHECK(b.normal_force[0] == Approx(-kBondKn * kDisc.area * stretch).epsilon(1e-9));
    CHECK(b.shear_force[0].norm() < 1e-12 * std::abs(b.normal_force[0]));
    CHECK(b.bend_moment[0].norm() == 0.0);
    CHECK(b.twist_moment[0] == 0.0);
  }
  SECTION("shear: F_s = -k_s A U_s (Eq 2-30), turned with the contact plane") {
    sim::World world = prescribedPair({Vec3(0, v, 0), Vec3::Zero()}, bond(0, 1), dt);
    for (int s = 0; s < steps; ++s) world.step();
    const sim::BondState& b = world.bonds();
    const double slide =
        steps * v * dt;  // 1e-7 m against a 5e-3 m arm: the plane turns by 2e-5 rad
    CHECK(b.shear_force[0].norm() == Approx(kBondKs * kDisc.area * slide).epsilon(1e-4));
    CHECK(b.shear_force[0].y() < 0);  // resists the slide of ball 1 along +y
    CHECK(std::abs(b.shear_force[0].dot(b.normal[0])) < 1e-12 * b.shear_force[0].norm());
  }
  SECTION("bending: M_s = -k_n I theta_s (Eq 2-32)") {
    sim::World world = prescribedPair({Vec3::Zero(), Vec3(0, 0, w)}, bond(0, 1), dt);
    for (int s = 0; s < steps; ++s) world.step();
    const sim::BondState& b = world.bonds();
    CHECK(b.bend_moment[0].z() == Approx(-kBondKn * kDisc.inertia * steps * w * dt).epsilon(1e-9));
    CHECK(b.shear_force[0].norm() < 1e-9 * std::abs(b.bend_moment[0].z()) / kRadius);
    CHECK(b.twist_moment[0] == 0.0);
  }
  SECTION("twist: M_n = -k_s J theta_n (Eq 2-31 [R])") {
    sim::World world = prescribedPair({Vec3::Zero(), Vec3(w, 0, 0)}, bond(0, 1), dt);
    for (int s = 0; s < steps; ++s) world.step();
    const sim::BondState& b = world.bonds();
    CHECK(b.twist_moment[0] == Approx(-kBondKs * kDisc.polar * steps * w * dt).epsilon(1e-9));
    CHECK(b.bend_moment[0].norm() == 0.0);
  }
}

TEST_CASE("bond: breaks at the first step its peak stress reaches the strength, in each mode",
          "[bonds]") {
  const double dt = 1e-7, v = 0.01, w = 2.0;
  struct Case {
    const char* name;
    Prescribed motion;
    double stress_per_step;  // Pa added to the governing peak stress by each step
    bool tensile;            // governed by sigma_max (else tau_max)
  };
  const Case cases[] = {
      {"tension", {Vec3(v, 0, 0), Vec3::Zero()}, kBondKn * v * dt, true},
      {"shear", {Vec3(0, v, 0), Vec3::Zero()}, kBondKs * v * dt, false},
      {"bending", {Vec3::Zero(), Vec3(0, 0, w)}, kBondKn * kRadius * w * dt, true},
      {"twist", {Vec3::Zero(), Vec3(w, 0, 0)}, kBondKs * kRadius * w * dt, false},
  };
  for (const sim::BondFailureRule rule :
       {sim::BondFailureRule::Stress, sim::BondFailureRule::Combined}) {
    for (const Case& c : cases) {
      // After update k (step k - 1) the stress is k x stress_per_step: with the
      // strength at 40.5 of them the bond must break in step 40 (its 41st update).
      const double strength = 40.5 * c.stress_per_step;
      const sim::BondSpec spec =
          c.tensile ? bond(0, 1, strength, 1e30) : bond(0, 1, 1e30, strength);
      sim::World world = prescribedPair(c.motion, spec, dt, rule);
      for (int s = 0; s < 60; ++s) world.step();
      INFO(
          c.name << (rule == sim::BondFailureRule::Stress ? " (stress rule)" : " (combined rule)"));
      REQUIRE(world.bondBreaks().size() == 1);
      const sim::BondBreak& e = world.bondBreaks()[0];
      CHECK(e.step == 40);
      CHECK(e.mode == (c.tensile ? sim::BondFailureMode::Tensile : sim::BondFailureMode::Shear));
      const double peak = c.tensile ? e.tensile_stress : e.shear_stress;
      CHECK(peak >= strength);
      CHECK(peak == Approx(41 * c.stress_per_step).epsilon(1e-3));
      CHECK(world.intactBonds() == 0);
      CHECK(world.bonds().intact[0] == 0);
    }
  }
}

TEST_CASE("bond: compression never breaks a bond", "[bonds]") {
  for (const sim::BondFailureRule rule :
       {sim::BondFailureRule::Stress, sim::BondFailureRule::Combined}) {
    // 1 Pa strengths: any tension or shear would break it at once.
    sim::World world =
        prescribedPair({Vec3(-0.01, 0, 0), Vec3::Zero()}, bond(0, 1, 1.0, 1.0), 1e-7, rule);
    for (int s = 0; s < 1000; ++s) world.step();
    CHECK(world.intactBonds() == 1);
    CHECK(world.bonds().normal_force[0] > 0);  // compressed by 1e-6 m
  }
}

TEST_CASE("bond: a bond broken in its first step leaves exactly the unbonded pair", "[bonds]") {
  // Two balls overlapping and separating, with friction and dashpots; the bond's
  // strength is below its first increment, so it breaks at step 0 and must have
  // carried nothing (a bug other codes shipped: the first step's bond force).
  sim::Model model = bondModel();
  model.materials[0].friction = 0.5;
  model.contact.damping_normal = model.contact.damping_shear = 0.2;
  model.timestep.dt = 1e-7;  // one step for both worlds (the bond would lower the automatic one)
  auto a = test::sphere(Vec3(0, 0, 0), kRadius);
  auto b = test::sphere(Vec3(2 * kRadius - 1e-6, 0, 0), kRadius, Vec3(-0.05, 0.02, 0.01));
  b.omega = Vec3(3, -1, 2);
  auto run = [&](bool bonded) {
    std::vector<sim::BondSpec> bonds;
    if (bonded) bonds.push_back(bond(0, 1, 1e-12, 1e-12));
    sim::World world(model, {a, b}, {}, bonds, 1);
    for (int s = 0; s < 3000; ++s)
      world.step(s % 100 == 7 ? [](const sim::Snapshot&) {}
                              : std::function<void(const sim::Snapshot&)>{});
    if (bonded) {
      REQUIRE(world.bondBreaks().size() == 1);
      CHECK(world.bondBreaks()[0].step == 0);
    }
    return world.stateHash();
  };
  CHECK(run(true) == run(false));
}

namespace {

/// A constant force (N) on one ball: the tip load of the cantilevers.
class TipLoad : public sim::ForceContribution {
 public:
  TipLoad(std::uint32_t ball, Vec3 force) : ball_(ball), force_(force) {}
  std::string name() const override { return "tip load"; }
  void addForces(const sim::ForceInput&, std::span<Vec3> force, std::span<Vec3>) override {
    force[ball_] += force_;
  }
  // A constant load is conservative: its potential -P.x keeps the energy check honest.
  double potentialEnergy(const sim::ForceInput& in) const override {
    return -force_.dot(in.particles.position[ball_]);
  }

 private:
  std::uint32_t ball_;
  Vec3 force_;
};

/// Tip deflection (m) of a cantilever of `balls` bonded spheres along x, the
/// first clamped (immovable), the last loaded by P along z, settled by local damping.
double cantileverDeflection(int balls, double load) {
  sim::Model model = bondModel();
  model.materials.push_back({"anchor", 1e30, 1e6, 1e6, 0.0, 0.0, 0.2});
  model.contact.local_damping = 0.7;
  std::vector<sim::SphereSpec> spheres;
  std::vector<sim::BondSpec> bonds;
  // A 1 um gap between neighbours: the bonds alone carry the load.
  const double pitch = 2 * kRadius + 1e-6;
  for (int i = 0; i < balls; ++i) {
    spheres.push_back(test::sphere(Vec3(i * pitch, 0, 0), kRadius, Vec3::Zero(), i == 0 ? 2 : 0));
    if (i > 0)
      bonds.push_back(bond(static_cast<std::uint32_t>(i - 1), static_cast<std::uint32_t>(i)));
  }
  sim::World world(model, spheres, {}, bonds, 1);
  const auto tip = static_cast<std::uint32_t>(balls - 1);
  world.addForceContribution(std::make_shared<TipLoad>(tip, Vec3(0, 0, load)));
  const double m = 2700.0 * 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  // Slowest mode: the tip stiffness of the equivalent beam (3 E I / L^3, E = k_n
  // pitch) on the chain's mass; settle for 40 of its periods (local damping 0.7
  // needs a few).
  const double length = (balls - 1) * pitch;
  const double k_tip = 3.0 * kBondKn * pitch * kDisc.inertia / std::pow(length, 3);
  const double period = 2 * std::numbers::pi * std::sqrt((balls - 1) * m / k_tip);
  const auto steps = static_cast<int>(40 * period / world.dt());
  for (int s = 0; s < steps; ++s) world.step();
  return world.particles().position[tip].z();
}

/// Exact small-deflection tip deflection of the discrete model: rigid spheres
/// of radius R joined by bonds with a bending spring k_n I and a shear spring
/// k_s A at the middle of each gap. Bond j carries the shear P and the moment
/// P (L - x_j); ball j+1 turns by M_j / (k_n I) more than ball j, and its centre
/// sits theta_j a + theta_{j+1} a + P / (k_s A) higher (a = pitch / 2).
double discreteDeflection(int balls, double load, double pitch) {
  double theta = 0.0, w = 0.0;
  const double length = (balls - 1) * pitch;
  for (int j = 0; j + 1 < balls; ++j) {
    const double x_bond = (j + 0.5) * pitch;
    const double next_theta = theta + load * (length - x_bond) / (kBondKn * kDisc.inertia);
    w += 0.5 * pitch * (theta + next_theta) + load / (kBondKs * kDisc.area);
    theta = next_theta;
  }
  return w;
}

}  // namespace

TEST_CASE("bond: cantilevers of bonded spheres against beam theory", "[bonds]") {
  const double pitch = 2 * kRadius + 1e-6, load = 0.5;  // N
  SECTION("two spheres: one bond's shear and bending compliance") {
    const double expected = load / (kBondKs * kDisc.area) +
                            load * (0.5 * pitch) * (0.5 * pitch) / (kBondKn * kDisc.inertia);
    CHECK(expected == Approx(discreteDeflection(2, load, pitch)));
    CHECK(cantileverDeflection(2, load) == Approx(expected).epsilon(2e-3));
  }
  SECTION("eleven spheres: Timoshenko beam with E = k_n x pitch, G = k_s x pitch") {
    const double got = cantileverDeflection(11, load);
    CHECK(got == Approx(discreteDeflection(11, load, pitch)).epsilon(2e-3));
    // The continuum beam of the same length: P L^3 / (3 E I) + P L / (G A).
    const double length = 10 * pitch;
    const double beam = load * std::pow(length, 3) / (3 * kBondKn * pitch * kDisc.inertia) +
                        load * length / (kBondKs * pitch * kDisc.area);
    CHECK(got == Approx(beam).epsilon(0.02));
  }
}

TEST_CASE("bond: a bonded chain's longest mode follows the chain's dispersion relation",
          "[bonds]") {
  // A free chain of N balls on springs k = k_n A: longitudinal mode j has
  // omega_j = 2 sqrt(k/m) sin(j pi / 2N); the long-wave speed is c = pitch sqrt(k/m).
  const int n = 20;
  const double pitch = 2 * kRadius * 1.001;  // gaps: no contact, the bonds alone
  sim::Model model = bondModel();
  std::vector<sim::SphereSpec> spheres;
  std::vector<sim::BondSpec> bonds;
  const double v0 = 1e-3;  // m/s: amplitude v0 / omega = 0.1 um, far below the 5 um gaps
  for (int i = 0; i < n; ++i) {
    const double shape = std::cos(std::numbers::pi * (i + 0.5) / n);
    spheres.push_back(test::sphere(Vec3(i * pitch, 0, 0), kRadius, Vec3(v0 * shape, 0, 0)));
    if (i > 0)
      bonds.push_back(bond(static_cast<std::uint32_t>(i - 1), static_cast<std::uint32_t>(i)));
  }
  sim::World world(model, spheres, {}, bonds, 1);
  const double m = 2700.0 * 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  const double omega0 = std::sqrt(kBondKn * kDisc.area / m);
  const double omega1 = 2 * omega0 * std::sin(std::numbers::pi / (2 * n));
  // Zero crossings of the end ball's velocity: half a period apart.
  std::vector<double> crossings;
  double last_v = v0, last_t = 0;
  const auto steps = static_cast<int>(3.2 * 2 * std::numbers::pi / omega1 / world.dt());
  for (int s = 0; s < steps; ++s)
    world.step([&](const sim::Snapshot& snap) {
      const double vx = snap.velocity[0].x();
      if ((vx > 0) != (last_v > 0))
        crossings.push_back(last_t + (snap.time - last_t) * last_v / (last_v - vx));
      last_v = vx;
      last_t = snap.time;
    });
  REQUIRE(crossings.size() >= 5);
  const double half_period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  const double measured = std::numbers::pi / half_period;
  INFO("omega_1 " << omega1 << " rad/s, measured " << measured << "; c = " << pitch * omega0
                  << " m/s");
  CHECK(measured == Approx(omega1).epsilon(2e-3));
  // Phase speed of the mode against the long-wave speed c (dispersion, 0.1 % here).
  const double phase_speed = measured / (std::numbers::pi / (n * pitch));
  CHECK(phase_speed == Approx(pitch * omega0).epsilon(5e-3));
}

namespace {

/// Rows of bonded balls resting on a floor and pulled apart: bonds break, in
/// order, on both halves of a two-thread team. `reach` > 1 also bonds each ball
/// to the balls up to `reach` places further along its half of the row (strong
/// bonds that hold): more bonds than balls.
struct BreakingRows {
  sim::Model model;
  std::vector<sim::SphereSpec> spheres;
  std::vector<sim::BondSpec> bonds;
  BreakingRows(int rows, int per_row, int reach = 1) {
    model = bondModel();
    model.gravity = Vec3(0, 0, -9.81);
    model.walls = {test::floorPlane(0.0)};
    model.materials[0].friction = 0.3;
    model.contact.damping_normal = model.contact.damping_shear = 0.1;
    const double pitch = 2 * kRadius;
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < per_row; ++x) {
        // The two halves of each row move apart; the middle bond's strength varies by row.
        const double vx = (x < per_row / 2 ? -1.0 : 1.0) * 0.05 * (1 + (y % 4));
        if (x > 0) {
          const bool middle = x == per_row / 2;
          const double strength = middle ? 2e5 * (1 + y % 7) : 6e7;
          bonds.push_back(bond(static_cast<std::uint32_t>(spheres.size() - 1),
                               static_cast<std::uint32_t>(spheres.size()), strength, strength));
        }
        for (int back = 2; back <= reach && x - back >= 0; ++back)
          if ((x - back < per_row / 2) == (x < per_row / 2))
            bonds.push_back(bond(static_cast<std::uint32_t>(spheres.size() - back),
                                 static_cast<std::uint32_t>(spheres.size()), 6e7, 6e7));
        spheres.push_back(
            test::sphere(Vec3(pitch * x, 3 * kRadius * y, kRadius), kRadius, Vec3(vx, 0, 0)));
      }
  }
};

}  // namespace

TEST_CASE("bond: bitwise the same on one and two threads while bonds break", "[bonds]") {
  const BreakingRows scene(60, 100);  // 6000 balls: two threads need >= 2000
  const auto [one, broken_one, t1, b1] =
      test::runWithBreaks(scene.model, scene.spheres, scene.bonds, 1);
  const auto [two, broken_two, t2, b2] =
      test::runWithBreaks(scene.model, scene.spheres, scene.bonds, 2);
  REQUIRE(t1 == 1);
  if (t2 < 2)
    WARN("this machine gives the world one thread only; the two-thread half is not exercised");
  CHECK(one == two);
  CHECK(broken_one == broken_two);
  CHECK(broken_one.size() > 10);                  // bonds did break
  CHECK(broken_one.size() < scene.bonds.size());  // and others held
}

TEST_CASE("bond: a world too small for two threads runs its many bonds on two, bitwise the same",
          "[bonds]") {
  // 1,900 balls (one thread: fewer than 2,000) and 5,491 bonds (two: 500 a thread).
  const BreakingRows scene(19, 100, 3);
  REQUIRE(scene.spheres.size() < 2000);
  REQUIRE(scene.bonds.size() >= 4000);
  const auto one = test::runWithBreaks(scene.model, scene.spheres, scene.bonds, 1);
  const auto two = test::runWithBreaks(scene.model, scene.spheres, scene.bonds, 2);
  REQUIRE(one.bond_threads == 1);
  CHECK(two.threads == 1);
  if (two.bond_threads < 2)
    WARN("this machine gives the bond stage one thread only; the two-thread half is not exercised");
  CHECK(one.hash == two.hash);
  CHECK(one.broken == two.broken);
  CHECK(one.broken.size() > 10);
  // One thread chosen (by the policy here, by the adaptive team's timing beside a
  // busy process) takes the bond stage to one thread as well.
  sim::World world(scene.model, scene.spheres, {}, scene.bonds, 2);
  world.setTeamPolicy(sim::TeamPolicy::Single);
  CHECK(world.bondThreads() == 1);
  world.setTeamPolicy(sim::TeamPolicy::Full);
  CHECK(world.bondThreads() == two.bond_threads);
}

TEST_CASE("bond: restart from a checkpoint with broken bonds equals the uninterrupted run",
          "[bonds]") {
  const BreakingRows scene(4, 30);
  const auto path = std::filesystem::temp_directory_path() / "rocklab_test_bonds_restart.h5";
  sim::World whole(scene.model, scene.spheres, {}, scene.bonds, 1);
  for (int s = 0; s < 1500; ++s) whole.step();
  sim::World first(scene.model, scene.spheres, {}, scene.bonds, 1);
  for (int s = 0; s < 700; ++s) first.step();
  const std::size_t broken_at_checkpoint = first.bondBreaks().size();
  REQUIRE(broken_at_checkpoint > 0);
  sim::output::writeCheckpoint(path, first.exportState(), "scene");
  auto cp = sim::output::readCheckpoint(path);
  std::filesystem::remove(path);
  sim::World second(scene.model, std::move(cp.state), 1);
  CHECK(second.intactBonds() == first.intactBonds());
  for (int s = 700; s < 1500; ++s) second.step();
  CHECK(second.stateHash() == whole.stateHash());
  CHECK(second.intactBonds() == whole.intactBonds());
  CHECK(second.bonds().normal_force == whole.bonds().normal_force);
  // Broken bonds stayed broken: the restarted run logged only the later breaks.
  CHECK(second.bondBreaks().size() + broken_at_checkpoint == whole.bondBreaks().size());
}

TEST_CASE("bond: run.h5 frames record the breakage - the reader gives the fragments back",
          "[bonds][output]") {
  // The tension case above: the bond breaks in step 40.
  const double dt = 1e-7, v = 0.01;
  sim::World world = prescribedPair({Vec3(v, 0, 0), Vec3::Zero()},
                                    bond(0, 1, 40.5 * kBondKn * v * dt, 1e30), dt);
  const auto dir = std::filesystem::temp_directory_path() /
                   ("rocklab-test-bonds-runfile-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  {
    sim::output::RunFile run(dir / "run.h5", "scene");
    for (int s = 0; s < 60; ++s)
      world.step(s % 20 == 0 ? [&](const sim::Snapshot& snap) { run.writeFrame(snap); }
                             : std::function<void(const sim::Snapshot&)>{});
    run.close(false);
  }
  REQUIRE(world.bondBreaks().size() == 1);
  sim::output::RunFileReader reader(dir / "run.h5");
  REQUIRE(reader.frameCount() == 3);  // steps 0, 20, 40
  const std::vector<std::uint8_t> intact{1, 1, 0};
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("frame " << k);
    const sim::Snapshot& s = reader.frame(k);
    REQUIRE(s.bond_intact.size() == 1);
    CHECK(s.bond_a[0] == 0);
    CHECK(s.bond_b[0] == 1);
    CHECK(s.bond_intact[0] == intact[k]);
    const auto label = sim::bondedClusters(s.position.size(), s.bond_a, s.bond_b, s.bond_intact);
    CHECK(label == (intact[k] ? std::vector<std::uint32_t>{0, 0} : std::vector<std::uint32_t>{0, 1}));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("bond: removal drops the bonds of removed balls and renumbers the rest", "[bonds]") {
  const BreakingRows scene(1, 6);  // bonds 0-1, 1-2, ..., 4-5
  sim::World world(scene.model, scene.spheres, {}, scene.bonds, 1);
  std::vector<bool> remove(6, false);
  remove[2] = true;
  const sim::WorldState s = sim::withoutBalls(world.exportState(), remove);
  REQUIRE(s.bonds.size() == 3);  // 0-1, 3-4 -> 2-3, 4-5 -> 3-4
  CHECK(s.bonds.a == std::vector<std::uint32_t>{0, 2, 3});
  CHECK(s.bonds.b == std::vector<std::uint32_t>{1, 3, 4});
  sim::World rebuilt(scene.model, s, 1);
  CHECK(rebuilt.intactBonds() == 3);
}

TEST_CASE("bond: the bonds' springs enter the time-step audit and the network check", "[bonds]") {
  sim::Model model = bondModel();
  auto a = test::sphere(Vec3(0, 0, 0), kRadius);
  auto b = test::sphere(Vec3(2 * kRadius, 0, 0), kRadius);
  const sim::World loose(model, {a, b}, 1);
  const sim::World bonded(model, {a, b}, {}, {bond(0, 1)}, 1);
  const double m = 2700.0 * 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  CHECK(loose.timestepAudit().bond_translational == 0.0);
  CHECK(bonded.timestepAudit().bond_translational == Approx(std::sqrt(m / (kBondKn * kDisc.area))));
  CHECK(bonded.timestepAudit().critical <= bonded.timestepAudit().bond_translational);
  CHECK(bonded.dt() < loose.dt());  // the bond (9.8e7 N/m) is stiffer than the contact (1e6 N/m)

  // A step forced far above the bond's: the network check stops it.
  model.timestep.dt = 3.0 * bonded.timestepAudit().bond_translational;
  model.timestep.allow_unsafe = true;
  model.watchdog.network_interval = 1;
  b.velocity = Vec3(1e-3, 0, 0);
  sim::World unstable(model, {a, b}, {}, {bond(0, 1)}, 1);
  try {
    for (int s = 0; s < 50; ++s) unstable.step();
    FAIL("the bond too stiff for the step was not stopped");
  } catch (const sim::WatchdogError& e) {
    CHECK_THAT(e.what(), Catch::Contains("unstable for the contact network"));
  }
}

TEST_CASE("bond: bad bonds are refused with the bond and the reason", "[bonds]") {
  sim::Model model = bondModel();
  const std::vector<sim::SphereSpec> balls{test::sphere(Vec3(0, 0, 0), kRadius),
                                           test::sphere(Vec3(2 * kRadius, 0, 0), kRadius)};
  auto message = [&](const sim::Model& m, sim::BondSpec spec) {
    try {
      sim::World w(m, balls, {}, {spec}, 1);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(message(model, bond(0, 7)), Catch::Contains("bond 0: ball 7 does not exist"));
  CHECK_THAT(message(model, bond(1, 1)), Catch::Contains("joins ball 1 to itself"));
  CHECK_THAT(message(model, bond(0, 1, -5.0)), Catch::Contains("strengths must be > 0"));
  sim::Model soft = model;
  soft.bonds.normal_stiffness = 0;
  CHECK_THAT(message(soft, bond(0, 1)), Catch::Contains("bonds.normal_stiffness = 0"));
  // Energy of a stretched bond: F^2 / (2 k_n A).
  sim::World world = prescribedPair({Vec3(0.01, 0, 0), Vec3::Zero()}, bond(0, 1), 1e-7);
  for (int s = 0; s < 10; ++s) world.step();
  double bond_energy = -1;
  world.step([&](const sim::Snapshot& snap) { bond_energy = snap.energy.bond; });
  const double f = world.bonds().normal_force[0];
  CHECK(bond_energy == Approx(0.5 * f * f / (kBondKn * kDisc.area)).epsilon(1e-9));
}
