// Stability: mass ratios up to 1e4 (a light ball between two 28 mm rocks; a
// 4 mm fragment on a 1e13 N/m moving wall; a fragment squeezed by a wall),
// clumps with nearly coincident members, a clump spinning fast.
#include <catch2/catch.hpp>

#include "rocklab/geometry/clump_shape.h"
#include "rocklab/sim/timestep.h"
#include "stability_support.h"

using namespace rocklab;
using namespace rocklab::stab;

TEST_CASE("mass ratio 1e2 to 1e4: a light ball between two rocks on a floor", "[stability]") {
  // Floor, rock, light ball, rock on one vertical line; the top rock lands on the
  // light ball at 1 m/s. Study stiffness 1e9 N/m and damping 0.11 (average-mass
  // dashpot: on the light ball it acts sqrt(M / 2m) times harder than beta says).
  for (double ratio : {1e2, 1e3, 1e4}) {
    INFO("mass ratio " << ratio);
    sim::Model model = linearPair(1e9, 0.37, 0.11);
    model.gravity = Vec3(0, 0, -9.81);
    model.walls.push_back(plane("floor", Vec3::Zero(), Vec3::UnitZ()));
    const double R = kRock, r = R / std::cbrt(ratio);
    const double z1 = R, z2 = z1 + R + r, z3 = z2 + r + R + 1e-6;
    sim::World w(model, {sphere({0, 0, z1}, R), sphere({0, 0, z2}, r), sphere({0, 0, z3}, R, {0, 0, -1.0})}, 1);
    const Outcome o = run(w, 20000, 20);
    REQUIRE(o.finite);
    REQUIRE_FALSE(o.stopped);
    // Largest overlap on the light ball: the top rock's 1 m/s impact, v sqrt(M / (2 k)) at most.
    const double bound = 1.0 * std::sqrt(sphereMass(R) / (2 * 1e9)) / r;
    CHECK(o.max_overlap < 1.2 * bound);
    CHECK(o.e_max <= o.e_first + 1e-6 * std::abs(o.e_first));
    const auto& x = w.particles().position;
    CHECK(std::abs(x[1].x()) + std::abs(x[1].y()) < 1e-9);  // the light ball stays on the axis
    figure("mass ratio " + num(ratio) + " light ball between rocks",
           "stable: overlap " + num(o.max_overlap, 3) + " of its radius (bound " + num(bound, 3) + "), dt " +
               num(w.dt(), 3) + " s = " + num(w.dt() / w.timestepAudit().critical, 3) + " x critical" +
               (w.dt() < 0.5 * w.timestepAudit().critical * (1 - 1e-9) ? " (damped cap)" : ""));
  }
}

TEST_CASE("damped cap: the old step (0.5 x critical) on the 1e4 fragment", "[stability]") {
  // What the automatic step was before the damped stability limit entered the
  // audit: 0.5 x the spring criterion. The light ball between rocks with the
  // study's dashpot, and two rocks with damping 1, run at that step.
  {
    sim::Model model = linearPair(1e9, 0.37, 0.11);
    model.gravity = Vec3(0, 0, -9.81);
    model.walls.push_back(plane("floor", Vec3::Zero(), Vec3::UnitZ()));
    const double R = kRock, r = R / std::cbrt(1e4);
    const double z1 = R, z2 = z1 + R + r, z3 = z2 + r + R + 1e-6;
    std::vector<sim::SphereSpec> s{sphere({0, 0, z1}, R), sphere({0, 0, z2}, r), sphere({0, 0, z3}, R, {0, 0, -1.0})};
    const sim::TimestepAudit audit = sim::World(model, s, 1).timestepAudit();
    CHECK(audit.automatic < 0.5 * audit.critical);  // the cap binds
    model.timestep.dt = 0.5 * audit.critical;
    model.timestep.allow_unsafe = true;
    sim::World w(model, s, 1);
    const Outcome o = run(w, 20000, 20);
    CHECK(o.finite);
    CHECK(o.stopped);  // the dashpot is unstable there; the watchdog must catch it
    figure("old step 0.5 x critical, fragment 1e4 with damping 0.11",
           o.stopped ? "stopped by the watchdog at step " + std::to_string(o.steps) + ": " + o.message.substr(0, 80) + "..."
                     : "NOT stopped: max speed " + num(o.max_speed));
  }
}

namespace {

/// A 4 mm fragment's world: 1e9 N/m fragment, a 1e13 N/m table (the crusher's
/// stiffness, infinitely heavy) oscillating z = kWallAmplitude sin(2 pi kWallFrequency t)
/// with A f^2 (2 pi)^2 = 3.2 m/s^2 < g, gravity, beta = 0.11.
constexpr double kWallAmplitude = 2e-6, kWallFrequency = 200.0;
sim::Model fragmentOnOscillatingWall() {
  sim::Model model = linearPair(1e9, 0.37, 0.11);
  model.materials[0].kn = model.materials[0].ks = 1e9;
  model.materials[1].kn = model.materials[1].ks = 1e13;
  model.gravity = Vec3(0, 0, -9.81);
  sim::Wall table = squareZ("table", Vec3::Zero(), 0.05);
  table.motion.amplitude = Vec3(0, 0, kWallAmplitude);
  table.motion.frequency = kWallFrequency;
  model.walls.push_back(table);
  return model;
}

void fragmentRidingWall(std::uint64_t steps, const std::string& name) {
  // The fragment must ride the wall, never leave it.
  const sim::Model model = fragmentOnOscillatingWall();
  const double A = kWallAmplitude, f = kWallFrequency;
  const double r = kFragment, k = 1e9 * 1e13 / (1e9 + 1e13), m = sphereMass(r);
  const double rest = m * 9.81 / k;
  const double w_peak = A * 2 * std::numbers::pi * f;
  sim::World w(model, {sphere({0, 0, r - rest}, r, {0, 0, w_peak})}, 1);  // moving with the wall
  double worst_gap = 0.0, worst_overlap = 0.0;
  const Outcome o = run(w, steps, 10, [&](const sim::Snapshot& s) {
    const double z_wall = A * std::sin(2 * std::numbers::pi * f * s.time);
    const double overlap = r - (s.position[0].z() - z_wall);
    worst_gap = std::max(worst_gap, -overlap);
    worst_overlap = std::max(worst_overlap, overlap);
    return false;
  });
  REQUIRE(o.finite);
  REQUIRE_FALSE(o.stopped);
  CHECK(worst_gap < 0.01 * A);               // rides the wall
  CHECK(worst_overlap < 5 * rest + 0.01 * A);  // pressed only by its weight and the wall's push
  CHECK(o.max_speed < 1.1 * w_peak);
  figure(name, "stable: largest gap " + num(worst_gap / A, 3) + " A, overlap " + num(worst_overlap / r, 3) +
                   " r, fastest " + num(o.max_speed / w_peak, 3) + " x wall peak speed over " + num(w.time(), 3) + " s");
}

}  // namespace

TEST_CASE("light 4 mm fragment riding a 1e13 N/m wall that oscillates at 200 Hz", "[stability]") {
  fragmentRidingWall(60000, "4 mm fragment on a 1e13 N/m wall at 200 Hz");
}

TEST_CASE("light 4 mm fragment riding a 1e13 N/m wall for 1e6 steps", "[stability][validation]") {
  fragmentRidingWall(1000000, "4 mm fragment on a 1e13 N/m wall at 200 Hz, 1e6 steps");
}

TEST_CASE("a wall squeezing a 4 mm fragment against the floor is stopped by the overlap watchdog", "[stability]") {
  // No equilibrium exists: the prescribed wall does unlimited work. The energy
  // check is off while a wall moves; the overlap limit must stop the run when
  // the gap reaches r (each side then overlaps r / 2), at t = (gap0 - r) / v.
  sim::Model model = linearPair(1e9, 0.37, 0.11);
  model.materials[1].kn = model.materials[1].ks = 1e13;
  model.walls.push_back(plane("floor", Vec3::Zero(), Vec3::UnitZ()));
  const double r = kFragment, v = 1.0, gap0 = 2 * r + 1e-5;
  sim::Wall lid = squareZ("lid", Vec3(0, 0, gap0), 0.01);
  std::swap(lid.vertices[1], lid.vertices[3]);  // face down
  lid.motion.velocity = Vec3(0, 0, -v);
  model.walls.push_back(lid);
  sim::World w(model, {sphere({0, 0, r}, r)}, 1);
  const Outcome o = run(w, 100000, 1000);
  REQUIRE(o.finite);
  REQUIRE(o.stopped);
  CHECK_THAT(o.message, Catch::Contains("overlap of particle 0 with wall") &&
                            Catch::Contains("above watchdog.max_overlap_fraction = 0.5"));
  const double expected = (gap0 - r) / v / w.dt();
  CHECK(static_cast<double>(o.steps) == Approx(expected).epsilon(0.01));
  figure("wall squeezing a 4 mm fragment at 1 m/s", "stopped by the watchdog at step " + std::to_string(o.steps) +
                                                        " (predicted " + num(expected, 5) + "): " +
                                                        o.message.substr(0, 100) + "...");
}

namespace {

sim::ClumpSpec clumpOf(const std::vector<geometry::Sphere>& members, const Vec3& at) {
  const geometry::ClumpMassProperties mp =
      geometry::clumpMassProperties(members, kDensity, geometry::ClumpMassDistribution::Union);
  sim::ClumpSpec c;
  c.position = at;
  c.mass = mp.mass;
  c.principal_inertia = mp.principal_moments;
  for (const geometry::Sphere& s : members)
    c.members.push_back({mp.principal_axes.transpose() * (s.centre - mp.centre_of_mass), s.radius});
  return c;
}

}  // namespace

TEST_CASE("clumps with nearly coincident members dropped on a floor", "[stability]") {
  const double r = 0.007;
  for (double eps : {0.0, 1e-12, 1e-9, 1e-6}) {
    INFO("member separation " << eps << " m");
    sim::Model model = linearPair(1e7, 0.37, 0.11);
    model.gravity = Vec3(0, 0, -9.81);
    model.walls.push_back(plane("floor", Vec3::Zero(), Vec3::UnitZ()));
    // Two members (almost) on top of each other and a third at one radius.
    const std::vector<geometry::Sphere> members{{Vec3(0, 0, 0), r}, {Vec3(eps, 0, 0), r}, {Vec3(r, 0, 0), r}};
    sim::ClumpSpec c = clumpOf(members, Vec3(0, 0, 0.03));
    c.orientation = geometry::Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
    sim::World w(model, {}, {c}, 1);
    const Outcome o = run(w, static_cast<std::uint64_t>(0.225 / w.dt()), 20);  // 0.225 s
    REQUIRE(o.finite);
    REQUIRE_FALSE(o.stopped);
    CHECK(o.e_max <= o.e_first + 1e-9);   // damped, no work input: never above the start
    CHECK(o.max_overlap < 0.05);
    const double z = w.particles().clumps.position[0].z();
    CHECK(z > 0.9 * r);                 // on the floor, not through it
    CHECK(z < 2.0 * r);
    CHECK(o.ke_last < 0.5 * (o.e_first - o.e_min));  // most of the drop's energy is gone
    figure("clump with members " + num(eps) + " m apart", "stable: landed, z " + num(z / r, 4) + " r, KE " +
                                                              num(o.ke_last, 3) + " J after " + num(w.time(), 3) + " s");
  }
}

TEST_CASE("four-ball clump spinning at 1e3 and 1e4 rad/s: free flight and landing", "[stability]") {
  const double r = 0.007;
  for (double spin : {1e3, 1e4}) {
    INFO("spin " << spin << " rad/s");
    sim::Model model = linearPair(1e7, 0.37, 0.11);
    model.gravity = Vec3(0, 0, -9.81);
    model.walls.push_back(plane("floor", Vec3::Zero(), Vec3::UnitZ()));
    sim::ClumpSpec c = clumpOf(geometry::fourBallClump(r), Vec3(0, 0, 0.05));
    c.omega = spin * Vec3(0.3, 1.0, 0.2).normalized();
    sim::World w(model, {}, {c}, 1);
    const double wdt = spin * w.dt();
    // Free flight until just before the floor: rotational energy and |L| kept.
    const auto& k = w.particles().clumps;
    const double L0 = k.angular_momentum[0].norm();
    const Outcome flight = run(w, 500, 1, {}, false);
    REQUIRE_FALSE(flight.stopped);
    CHECK(k.angular_momentum[0].norm() == Approx(L0).epsilon(1e-12));
    CHECK((flight.e_max - flight.e_min) <= 1e-3 * flight.e_first);
    // Then it lands spinning; friction and dashpots take energy, nothing adds it.
    const Outcome o = run(w, 40000, 20);
    REQUIRE(o.finite);
    REQUIRE_FALSE(o.stopped);
    CHECK(o.e_max <= flight.e_first * 1.02);
    CHECK(o.max_overlap < 0.5);
    // Friction turns spin into a throw: the clump leaves the floor, never faster
    // than all of its energy allows.
    const double v_up = k.velocity[0].norm();
    CHECK(0.5 * k.mass[0] * v_up * v_up <= flight.e_first);
    figure("four-ball clump spinning " + num(spin) + " rad/s",
           "stable: " + num(wdt, 3) + " rad per step; free flight: energy spread " +
               num((flight.e_max - flight.e_min) / flight.e_first, 3) + ", |L| kept to 1e-12; landing: energy max/start " +
               num(o.e_max / flight.e_first, 4) + ", thrown off at " + num(v_up, 3) + " m/s");
  }
}

namespace {

/// The 4 mm fragment riding the 1e13 N/m wall at 200 Hz with dt forced to f x critical.
Outcome fragmentOnWallForced(double f, double& w_peak) {
  sim::Model model = fragmentOnOscillatingWall();
  w_peak = kWallAmplitude * 2 * std::numbers::pi * kWallFrequency;
  const double r = kFragment;
  const std::vector<sim::SphereSpec> s{sphere({0, 0, r}, r, {0, 0, w_peak})};
  model.timestep.dt = f * sim::World(model, s, 1).timestepAudit().critical;
  model.timestep.allow_unsafe = true;
  sim::World w(model, s, 1);
  return run(w, 60000, 10);
}

}  // namespace

TEST_CASE("forced 10 x critical step with a moving wall: stopped by the energy check counting the wall's work", "[stability]") {
  // Before the energy check counted the work of moving walls it was off whenever
  // a wall moved: this fragment bounced off the wall ever faster for 60000 steps
  // and nothing stopped it.
  double w_peak = 0;
  const Outcome o = fragmentOnWallForced(10.0, w_peak);
  REQUIRE(o.finite);
  REQUIRE(o.stopped);
  CHECK_THAT(o.message, Catch::Contains("mechanical energy grew") &&
                            Catch::Contains("J of work done by the moving walls") &&
                            Catch::Contains("x the critical step"));
  CHECK(o.steps <= 10000);
  figure("forced dt 10 x critical, fragment on the moving 1e13 N/m wall",
         "stopped by the watchdog at step " + std::to_string(o.steps) + ": " + o.message.substr(0, 150) + "...");
}

// At 3 x critical the damped normal mode of the resting fragment is unstable
// (a^2 + 2b = 4.45 > 4): it hops at ~20 x the wall's speed, but its energy
// (1e-7 J) stays below 10 % of the energy scale of one 4 mm ball (m g x 2r =
// 3.6e-6 J), so the energy check never saw it. The contact-network check does, at
// the first check that finds the fragment touching the wall.
TEST_CASE("forced 3 x critical step with a moving wall: stopped by the contact-network check", "[stability]") {
  double w_peak = 0;
  const Outcome o = fragmentOnWallForced(3.0, w_peak);
  REQUIRE(o.finite);
  REQUIRE(o.stopped);
  CHECK_THAT(o.message, Catch::Contains("the step is unstable for the contact network"));
  CHECK(o.steps <= 1000);
  figure("forced dt 3 x critical, fragment on the moving 1e13 N/m wall",
         "stopped by the watchdog at step " + std::to_string(o.steps) + ": " + o.message.substr(0, 110) + "...");
}
