// Contact bonds (sim/bonds.h, dem-models.md §8.1). As in test_bonds.cpp, the
// prescribed-motion cases give the two balls an enormous mass, so no force can
// change their motion: every step moves them by exactly V dt, and the bond's
// springs after N steps are known in closed form, so is the step it breaks.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "rocklab/sim/output/checkpoint.h"
#include "sim/support.h"

using namespace rocklab;
using geometry::Vec3;

namespace {

constexpr double kRadius = 0.0025;  // m
constexpr double kBallK = 1e6;      // N/m, each ball's k_n = k_s (linear law)
constexpr double kPairK = 0.5 * kBallK;  // N/m, K^n = K^s of the pair (Eq 2-20, 2-21)

sim::BondSpec glue(std::uint32_t a, std::uint32_t b, double normal = INFINITY, double shear = INFINITY) {
  return sim::BondSpec{a, b, normal, shear, sim::BondKind::Contact};
}

/// Two balls along x, `overlap` (m; < 0 a gap) apart from touch, the second moving
/// at `velocity`, both immovable by forces; friction mu; fixed step dt.
sim::World prescribedPair(const Vec3& velocity, double overlap, std::vector<sim::BondSpec> bonds,
                          double dt, double mu = 0.3) {
  sim::Model model = test::linearModel(kBallK, mu);
  model.materials[0].density = 1e30;
  model.timestep.dt = dt;
  model.bonds.normal_stiffness = 5e12;  // Pa/m, for a parallel bond beside (Table 5.2)
  model.bonds.shear_stiffness = 2e12;
  auto a = test::sphere(Vec3(0, 0, 0), kRadius);
  auto b = test::sphere(Vec3(2 * kRadius - overlap, 0, 0), kRadius, velocity);
  return sim::World(model, {a, b}, {}, bonds, 1);
}

/// The pair's ordinary contact shear spring (force on ball 0), from the exported
/// history; zero when the pair has none.
Vec3 contactShear(const sim::World& world) {
  for (const sim::PairHistory& h : world.exportState().pair_history)
    if (h.i == 0 && h.j == 1) return h.shear;
  return Vec3::Zero();
}

/// Total force (N) on ball 1 at the next step.
Vec3 forceOnSecond(sim::World& world) {
  Vec3 f = Vec3::Zero();
  world.step([&](const sim::Snapshot& s) { f = s.force[1]; });
  return f;
}

std::filesystem::path tempFile(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("rocklab_" + name + "_" + std::to_string(::getpid()) + ".h5");
}

}  // namespace

TEST_CASE("contact bond: pulled apart it carries tension K^n x gap, breaks at F_c^n, then nothing",
          "[bonds]") {
  const double dt = 1e-7, v = 0.01;              // s, m/s
  const double per_step = kPairK * v * dt;       // N of tension added by each step's opening
  const double strength = 40.5 * per_step;       // F_c^n: reached at a gap of 41 steps
  sim::World world = prescribedPair(Vec3(v, 0, 0), 0.0, {glue(0, 1, strength, 1e30)}, dt);
  REQUIRE(world.bonds().kind[0] == static_cast<std::uint8_t>(sim::BondKind::Contact));
  CHECK(world.bonds().spring_normal[0] == kPairK);
  CHECK(world.bonds().spring_shear[0] == kPairK);
  for (int s = 0; s < 30; ++s) world.step();
  // The 31st step (step 30) sees a gap of 30 v dt.
  double bond_energy = -1;
  world.step([&](const sim::Snapshot& snap) { bond_energy = snap.energy.bond; });
  const sim::BondState& b = world.bonds();
  const double gap_seen = 30 * v * dt;
  CHECK(b.normal_force[0] == Approx(-kPairK * gap_seen).epsilon(1e-9));
  CHECK(bond_energy == Approx(0.5 * b.normal_force[0] * b.normal_force[0] / kPairK).epsilon(1e-9));
  CHECK(world.intactBonds() == 1);
  for (int s = 31; s < 60; ++s) world.step();
  REQUIRE(world.bondBreaks().size() == 1);
  const sim::BondBreak& e = world.bondBreaks()[0];
  CHECK(e.step == 41);
  CHECK(e.kind == sim::BondKind::Contact);
  CHECK(e.mode == sim::BondFailureMode::Tensile);
  CHECK(-e.normal_force >= strength);
  CHECK(-e.normal_force == Approx(41 * per_step).epsilon(1e-6));
  CHECK(e.tensile_stress == 0.0);
  // Broken: apart, the ordinary contact carries nothing.
  CHECK(forceOnSecond(world).norm() == 0.0);
  CHECK(world.intactBonds() == 0);
}

TEST_CASE("contact bond: a parallel bond beside it holds on when the contact bond breaks",
          "[bonds]") {
  const double dt = 1e-7, v = 0.01;
  const double strength = 10.5 * kPairK * v * dt;
  sim::World world = prescribedPair(
      Vec3(v, 0, 0), 0.0, {sim::BondSpec{0, 1, 1e30, 1e30}, glue(0, 1, strength, 1e30)}, dt);
  for (int s = 0; s < 30; ++s) world.step();
  REQUIRE(world.bondBreaks().size() == 1);
  CHECK(world.bondBreaks()[0].bond == 1);
  CHECK(world.bonds().intact[0] == 1);
  CHECK(world.bonds().normal_force[0] < 0);  // the parallel bond in tension
  // Its force alone acts on ball 1 now (normal force along n = +x on b).
  const Vec3 force = forceOnSecond(world);
  CHECK(force.x() == Approx(world.bonds().normal_force[0]).epsilon(1e-6));
}

TEST_CASE("contact bond: sheared it does not slip beyond mu F_n and breaks at F_c^s - the slip "
          "rule takes over",
          "[bonds]") {
  const double dt = 1e-7, v = 0.01, mu = 0.3;
  const double per_step = kPairK * v * dt;  // N of shear spring per step
  // Compressed by an overlap whose friction limit is 5 steps of shear: mu K delta = 5 per_step.
  const double overlap = 5 * per_step / (mu * kPairK);
  const double strength = 40.5 * per_step;
  sim::World world = prescribedPair(Vec3(0, v, 0), overlap, {glue(0, 1, 1e30, strength)}, dt, mu);
  for (int s = 0; s < 30; ++s) world.step();
  const sim::BondState& b = world.bonds();
  CHECK(b.normal_force[0] == Approx(kPairK * overlap).epsilon(1e-4));
  // 30 updates of the shear spring, six times the friction limit: no slip.
  CHECK(b.shear_force[0].norm() == Approx(30 * per_step).epsilon(1e-4));
  CHECK(b.shear_force[0].y() < 0);  // resists the slide of ball 1 along +y
  CHECK(b.shear_force[0].norm() > 5 * mu * b.normal_force[0]);
  for (int s = 30; s < 45; ++s) world.step();
  REQUIRE(world.bondBreaks().size() == 1);
  const sim::BondBreak& e = world.bondBreaks()[0];
  CHECK(e.step == 40);
  CHECK(e.mode == sim::BondFailureMode::Shear);
  CHECK(e.shear_force >= strength);
  CHECK(e.shear_force == Approx(41 * per_step).epsilon(1e-4));
  // Beyond the friction limit: the ordinary contact slips at mu K^n U^n (Eq 2-39).
  const Vec3 s = contactShear(world);
  CHECK(s.norm() == Approx(mu * kPairK * overlap).epsilon(1e-4));
  CHECK(s.y() > 0);  // on ball 0: dragged along +y by ball 1
}

TEST_CASE("contact bond: a shear break under compression within the friction limit keeps the forces",
          "[bonds]") {
  const double dt = 1e-7, v = 0.01, mu = 0.9;
  const double per_step = kPairK * v * dt;
  const double overlap = 100 * per_step / (mu * kPairK);  // friction limit: 100 steps of shear
  const double strength = 20.5 * per_step;
  sim::World world = prescribedPair(Vec3(0, v, 0), overlap, {glue(0, 1, 1e30, strength)}, dt, mu);
  // Ball 1's force in the steps around the break (step 20).
  std::vector<Vec3> force;
  for (int s = 0; s < 30; ++s) force.push_back(forceOnSecond(world));
  REQUIRE(world.bondBreaks().size() == 1);
  REQUIRE(world.bondBreaks()[0].step == 20);
  // The shear force grows by K^s v dt every step, before, at and after the break;
  // the normal force stays K^n U^n: continuous.
  for (int s = 1; s < 30; ++s) {
    INFO("step " << s);
    CHECK(force[s].y() - force[s - 1].y() == Approx(-per_step).epsilon(1e-4));
    CHECK(force[s].x() == Approx(kPairK * overlap).epsilon(1e-5));
  }
  CHECK(contactShear(world).norm() == Approx(30 * per_step).epsilon(1e-4));
}

TEST_CASE("contact bond: a shear break in tension leaves no force", "[bonds]") {
  const double dt = 1e-7, v = 0.01;
  const double per_step = kPairK * v * dt;
  // Opening and sliding at once: tension grows, the shear spring reaches F_c^s first.
  sim::World world =
      prescribedPair(Vec3(0.2 * v, v, 0), 0.0, {glue(0, 1, 1e30, 10.5 * per_step)}, dt);
  for (int s = 0; s < 20; ++s) world.step();
  REQUIRE(world.bondBreaks().size() == 1);
  CHECK(world.bondBreaks()[0].mode == sim::BondFailureMode::Shear);
  CHECK(world.bondBreaks()[0].normal_force < 0);
  CHECK(forceOnSecond(world).norm() == 0.0);
  CHECK(contactShear(world).norm() == 0.0);
}

TEST_CASE("contact bond: compression never breaks it", "[bonds]") {
  // 0.1 N strengths, pushed together for 1000 steps: a 1e-6 m overlap, K^n U^n = 0.5 N.
  sim::World world = prescribedPair(Vec3(-0.1, 0, 0), 0.0, {glue(0, 1, 0.1, 0.1)}, 1e-8);
  for (int s = 0; s < 1000; ++s) world.step();
  CHECK(world.intactBonds() == 1);
  CHECK(world.bonds().normal_force[0] == Approx(0.5).epsilon(1e-3));
}

TEST_CASE("contact bond: broken at its first step it leaves exactly the unbonded pair", "[bonds]") {
  // Overlapping, approaching at an angle and spinning, with friction and dashpots;
  // the strengths are below the first step's shear spring, so it breaks at step 0.
  for (const bool hertz : {false, true}) {
    sim::Model model = test::linearModel(kBallK, 0.5, 0.2);
    if (hertz) {
      model.contact.law = sim::ContactLaw::HertzMindlin;
      model.materials[0].shear_modulus = model.materials[1].shear_modulus = 1e9;
    }
    model.timestep.dt = 1e-7;
    auto a = test::sphere(Vec3(0, 0, 0), kRadius);
    auto b = test::sphere(Vec3(2 * kRadius - 1e-6, 0, 0), kRadius, Vec3(-0.05, 0.02, 0.01));
    b.omega = Vec3(3, -1, 2);
    auto run = [&](bool bonded) {
      std::vector<sim::BondSpec> bonds;
      if (bonded) bonds.push_back(glue(0, 1, 1e-12, 1e-12));
      sim::World world(model, {a, b}, {}, bonds, 1);
      for (int s = 0; s < 3000; ++s)
        world.step(s % 100 == 7 ? [](const sim::Snapshot&) {}
                                : std::function<void(const sim::Snapshot&)>{});
      if (bonded) {
        REQUIRE(world.bondBreaks().size() == 1);
        CHECK(world.bondBreaks()[0].step == 0);
        CHECK(world.bondBreaks()[0].mode == sim::BondFailureMode::Shear);
      }
      return world.stateHash();
    };
    INFO((hertz ? "Hertz" : "linear"));
    CHECK(run(true) == run(false));
  }
}

namespace {

/// Rows of touching balls on a floor, contact-bonded along each row (every
/// other row with parallel bonds beside), the two halves of each row moving
/// apart: the middle bonds break, in order, on both halves of a two-thread team.
struct GluedRows {
  sim::Model model;
  std::vector<sim::SphereSpec> spheres;
  std::vector<sim::BondSpec> bonds;
  GluedRows(int rows, int per_row) {
    model = test::linearModel(kBallK, 0.3, 0.1);
    model.gravity = Vec3(0, 0, -9.81);
    model.walls = {test::floorPlane(0.0)};
    model.bonds.normal_stiffness = 5e12;
    model.bonds.shear_stiffness = 2e12;
    const double pitch = 2 * kRadius;
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < per_row; ++x) {
        const double vx = (x < per_row / 2 ? -1.0 : 1.0) * 0.05 * (1 + (y % 4));
        if (x > 0) {
          const auto i = static_cast<std::uint32_t>(spheres.size());
          const bool middle = x == per_row / 2;
          const double force = middle ? 0.02 * (1 + y % 7) : 1e3;  // N
          bonds.push_back(glue(i - 1, i, force, force));
          if (y % 2 == 1 && !middle) bonds.push_back(sim::BondSpec{i - 1, i, 6e7, 6e7});
        }
        spheres.push_back(
            test::sphere(Vec3(pitch * x, 3 * kRadius * y, kRadius), kRadius, Vec3(vx, 0, 0)));
      }
  }
};

}  // namespace

TEST_CASE("contact bond: bitwise the same on one and two threads while contact bonds break",
          "[bonds]") {
  const GluedRows scene(60, 100);  // 6000 balls: two threads need >= 2000
  const auto [one, broken_one, t1, b1] = test::runWithBreaks(scene.model, scene.spheres, scene.bonds, 1);
  const auto [two, broken_two, t2, b2] = test::runWithBreaks(scene.model, scene.spheres, scene.bonds, 2);
  REQUIRE(t1 == 1);
  if (t2 < 2)
    WARN("this machine gives the world one thread only; the two-thread half is not exercised");
  CHECK(one == two);
  CHECK(broken_one == broken_two);
  CHECK(broken_one.size() > 10);
  CHECK(broken_one.size() < scene.bonds.size());
}

TEST_CASE("contact bond: restart from a checkpoint with broken contact bonds equals the "
          "uninterrupted run",
          "[bonds]") {
  SECTION("rows pulled apart") {
    const GluedRows scene(4, 30);
    const auto path = tempFile("contact_bond_restart_rows");
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
    CHECK(second.bonds().shear_force == whole.bonds().shear_force);
    CHECK(second.bondBreaks().size() + broken_at_checkpoint == whole.bondBreaks().size());
  }
  SECTION("saved right after a shear break, its shear spring not yet handed to the contact") {
    const double dt = 1e-7, v = 0.01, mu = 0.9;
    const double per_step = kPairK * v * dt;
    const double overlap = 100 * per_step / (mu * kPairK);
    auto pair = [&] {
      sim::Model model = test::linearModel(kBallK, mu, 0.1);
      model.timestep.dt = dt;
      auto a = test::sphere(Vec3(0, 0, 0), kRadius);
      auto b = test::sphere(Vec3(2 * kRadius - overlap, 0, 0), kRadius, Vec3(0, v, 0));
      return std::pair{model, std::vector<sim::SphereSpec>{a, b}};
    };
    const auto [model, balls] = pair();
    const std::vector<sim::BondSpec> bonds{glue(0, 1, 1e30, 20.5 * per_step)};
    sim::World whole(model, balls, {}, bonds, 1);
    for (int s = 0; s < 400; ++s) whole.step();
    sim::World first(model, balls, {}, bonds, 1);
    while (first.bondBreaks().empty()) first.step();
    const auto path = tempFile("contact_bond_restart_handover");
    sim::output::writeCheckpoint(path, first.exportState(), "scene");
    auto cp = sim::output::readCheckpoint(path);
    std::filesystem::remove(path);
    sim::World second(model, std::move(cp.state), 1);
    CHECK(second.intactBonds() == 0);
    CHECK(contactShear(second) == contactShear(first));
    CHECK(contactShear(second).norm() > 0);
    for (auto s = second.stepCount(); s < 400; ++s) second.step();
    CHECK(second.stateHash() == whole.stateHash());
  }
}

TEST_CASE("contact bond: removal keeps the contact bonds of kept balls", "[bonds]") {
  const GluedRows scene(1, 6);
  sim::World world(scene.model, scene.spheres, {}, scene.bonds, 1);
  std::vector<bool> remove(6, false);
  remove[2] = true;
  const sim::WorldState s = sim::withoutBalls(world.exportState(), remove);
  REQUIRE(s.bonds.size() == 3);
  CHECK(s.bonds.kind == std::vector<std::uint8_t>{1, 1, 1});
  CHECK(s.bonds.a == std::vector<std::uint32_t>{0, 2, 3});
  sim::World rebuilt(scene.model, s, 1);
  CHECK(rebuilt.intactBonds() == 3);
}

TEST_CASE("contact bond: its springs enter the time-step audit and the network check", "[bonds]") {
  sim::Model model = test::linearModel(kBallK);
  auto a = test::sphere(Vec3(0, 0, 0), kRadius);
  auto b = test::sphere(Vec3(2 * kRadius, 0, 0), kRadius);
  const sim::World bonded(model, {a, b}, {}, {glue(0, 1)}, 1);
  const double m = 2730.0 * 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  CHECK(bonded.timestepAudit().bond_translational == Approx(std::sqrt(m / kPairK)));
  CHECK(bonded.timestepAudit().critical <= bonded.timestepAudit().bond_translational);

  // A step far above the bond's: the network check (bond springs included) stops it,
  // though the pair is not in the contact list.
  model.timestep.dt = 3.0 * bonded.timestepAudit().bond_translational;
  model.timestep.allow_unsafe = true;
  model.watchdog.network_interval = 1;
  b.velocity = Vec3(1e-3, 0, 0);
  sim::World unstable(model, {a, b}, {}, {glue(0, 1)}, 1);
  try {
    for (int s = 0; s < 50; ++s) unstable.step();
    FAIL("the contact bond too stiff for the step was not stopped");
  } catch (const sim::WatchdogError& e) {
    CHECK_THAT(e.what(), Catch::Contains("unstable for the contact network"));
  }
}

TEST_CASE("contact bond: bad contact bonds are refused with the bond and the reason", "[bonds]") {
  auto message = [](const sim::Model& m, std::vector<sim::BondSpec> bonds, double gap = 0.0) {
    const std::vector<sim::SphereSpec> balls{test::sphere(Vec3(0, 0, 0), kRadius),
                                             test::sphere(Vec3(2 * kRadius + gap, 0, 0), kRadius)};
    try {
      sim::World w(m, balls, {}, bonds, 1);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const sim::Model linear = test::linearModel(kBallK);
  // No parallel-bond stiffnesses needed without parallel bonds.
  CHECK(message(linear, {glue(0, 1, 1.0, 1.0)}) == "accepted");
  CHECK_THAT(message(linear, {glue(0, 1, -1.0, 1.0)}), Catch::Contains("strengths must be > 0 N"));
  CHECK_THAT(message(linear, {glue(0, 1), glue(1, 0)}), Catch::Contains("two contact bonds"));
  CHECK_THAT(message(linear, {glue(0, 1), sim::BondSpec{0, 1}}),
             Catch::Contains("bonds.normal_stiffness = 0"));
  sim::Model hertz = linear;
  hertz.contact.law = sim::ContactLaw::HertzMindlin;
  hertz.materials[0].shear_modulus = hertz.materials[1].shear_modulus = 1e9;
  CHECK_THAT(message(hertz, {glue(0, 1)}, 1e-6), Catch::Contains("needs its balls 0 and 1 to overlap"));
  CHECK(message(hertz, {glue(0, 1)}, -1e-6) == "accepted");
}
