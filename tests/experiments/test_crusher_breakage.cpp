// Population-balance breakage in the crusher run (experiments.md §g.6): the
// strength draw, the split, one ball breaking between two closing walls with
// the freeze, the scene keys, and a tiny crusher run with breakage.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>

#include "cli_support.h"
#include "crusher/breakage_freeze.h"
#include "crusher/breakage_model.h"
#include "crusher_support.h"
#include "drivers/crusher_breakage.h"
#include "drivers/crusher_experiment.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/sim/particle_stress.h"

namespace fs = std::filesystem;
using namespace rocklab;
using namespace rocklab::experiments;
using Catch::Matchers::Contains;
using geometry::Vec3;

TEST_CASE("breakage strength: the median of many draws is q0(d) (ln 2)^(1/m), the same id and seed the same strength",
          "[crusher]") {
  const crusher::StrengthLaw law;  // the reference's reading [I]: 25.2 MPa at 21 mm, b -1.1, m 2.65
  CHECK(law.scale(0.021) == Approx(25.2e6));
  // The quoted end values of §g.6 within 2 %: that is why d_ref = 21 mm.
  CHECK(law.scale(0.014) == Approx(38.6e6).epsilon(0.02));
  CHECK(law.scale(0.028) == Approx(18.2e6).epsilon(0.02));
  for (const double d : {0.006, 0.014, 0.028}) {
    const int n = 20001;
    std::vector<double> q;
    for (int id = 0; id < n; ++id) q.push_back(law.strength(d, crusher::uniformFromId(7, id)));
    std::nth_element(q.begin(), q.begin() + n / 2, q.end());
    // The median's sampling error: 0.5 / sqrt(n) in U, 0.4 % in q; 1.5 % is ~4 of them.
    INFO("d = " << d);
    CHECK(q[n / 2] == Approx(law.scale(d) * std::pow(std::log(2.0), 1 / law.weibull_modulus)).epsilon(0.015));
  }
  // Size effect: the smaller ball is stronger by (d1/d2)^b.
  CHECK(law.scale(0.014) / law.scale(0.028) == Approx(std::pow(0.5, -1.1)));
  // Counter-based: the draw of an id does not depend on which others were drawn.
  CHECK(crusher::uniformFromId(1, 42) == crusher::uniformFromId(1, 42));
  CHECK(crusher::uniformFromId(1, 42) != crusher::uniformFromId(2, 42));
  CHECK(crusher::uniformFromId(1, 42) != crusher::uniformFromId(1, 43));
  for (std::uint64_t id : {0ull, 1ull, ~0ull}) {
    const double u = crusher::uniformFromId(0, id);
    CHECK((u > 0 && u < 1));
  }
}

TEST_CASE("breakage split: mass and volume kept exactly, every fragment inside its parent on the minor direction",
          "[crusher]") {
  const Vec3 centre(0.1, -0.2, 0.3), direction = Vec3(1, 2, -2).normalized();
  const double radius = 0.0123, mass = 2650 * 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
  for (const crusher::SplitMode mode : {crusher::SplitMode::Triple, crusher::SplitMode::Equal}) {
    const auto offsets = crusher::defaultOffsets(mode);
    REQUIRE(crusher::offsetsProblem(mode, offsets).empty());
    const auto pieces = crusher::splitBall(centre, radius, mass, direction, mode, offsets);
    REQUIRE(pieces.size() == crusher::massFractions(mode).size());
    double m = 0, volume = 0;
    for (const auto& f : pieces) {
      m += f.mass;
      volume += std::pow(f.radius, 3);
      const Vec3 off = f.position - centre;
      CHECK(off.cross(direction).norm() <= 1e-15);  // on the line
      CHECK(off.norm() + f.radius <= radius * (1 + 1e-12));  // inside
      CHECK(f.mass / std::pow(f.radius, 3) == Approx(mass / std::pow(radius, 3)).epsilon(1e-14));  // same density
    }
    CHECK(m == Approx(mass).epsilon(1e-15));
    CHECK(volume == Approx(std::pow(radius, 3)).epsilon(1e-14));
  }
  const auto triple = crusher::splitBall(centre, radius, mass, direction, crusher::SplitMode::Triple,
                                         crusher::defaultOffsets(crusher::SplitMode::Triple));
  CHECK(triple[0].mass == Approx(0.6 * mass));
  CHECK(triple[1].mass == Approx(0.3 * mass));
  CHECK(triple[2].radius == Approx(0.464 * radius).epsilon(1e-3));
  // Offsets that leave the parent, or one too few, are refused.
  CHECK_THAT(crusher::offsetsProblem(crusher::SplitMode::Equal, {-0.3, 0.2}), Contains("outside the parent"));
  CHECK_THAT(crusher::offsetsProblem(crusher::SplitMode::Triple, {0, 0}), Contains("needs 3 offsets"));
}

namespace {

/// One 20 mm ball between two planes closing on it at `speed` each (no gravity,
/// no friction, no damping), sliding along x at 0.01 m/s.
std::unique_ptr<sim::World> pinchedBall(double speed) {
  sim::Model m;
  m.materials.push_back({"rock", 2650, 1e9, 1e9, 0.0});
  m.materials.push_back({"steel", 7800, 1e13, 1e13, 0.0});
  m.gravity = Vec3::Zero();
  m.timestep.dt = 1.5e-7;  // holds the smallest fragment (checked by CrusherBreakage::start)
  const double r = 0.010;
  sim::Wall low, high;
  low.name = "low";
  low.point = Vec3(0, 0, -r);
  low.normal = Vec3::UnitZ();
  low.material = 1;
  low.motion.velocity = Vec3(0, 0, speed);
  high = low;
  high.name = "high";
  high.point = Vec3(0, 0, r);
  high.normal = -Vec3::UnitZ();
  high.motion.velocity = Vec3(0, 0, -speed);
  m.walls = {low, high};
  sim::SphereSpec s;
  s.radius = r;
  s.velocity = Vec3(0.01, 0, 0);
  return std::make_unique<sim::World>(m, std::vector<sim::SphereSpec>{s}, 1);
}

BreakageSettings pinchSettings() {
  BreakageSettings s;
  s.enabled = true;
  s.min_diameter = 0.015;  // the fragments (<= 16.9 mm of 20) do not break again
  s.offsets = crusher::defaultOffsets(s.mode);
  s.check_interval = 1e-9;  // every step
  return s;
}

double octahedral(const sim::World& w, std::size_t i) {
  return sim::octahedralShearStress(sim::principalStresses(w.particleStress()[i]));
}

sim::Energy energyAfterStep(std::unique_ptr<sim::World>& world) {
  sim::Energy e;
  world->step([&](const sim::Snapshot& s) { e = s.energy; });
  return e;
}

}  // namespace

TEST_CASE("the fragments' overlaps found through a grid, and their largest through a cell grid, equal those of every ball "
          "against every fragment, bit for bit",
          "[experiments][crusher]") {
  // A loose heap of 3,000 balls of 2-14 mm, a hundred of them fragments, many touching.
  sim::Model model;
  model.materials.emplace_back();
  model.materials.back().kn = 1e6;
  model.materials.push_back(model.materials.back());
  model.materials.back().kn = 3e5;  // the fragments' freeze stiffness
  sim::ParticleState p;
  geometry::Rng rng(7);
  std::vector<std::uint32_t> fragments;
  for (std::uint32_t i = 0; i < 3000; ++i) {
    const double r = rng.uniform(0.001, 0.007);
    const bool fragment = i % 30 == 0;
    // (fragmentOverlaps reads positions, radii and materials only)
    p.position.emplace_back(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-0.05, 0.05));
    p.radius.push_back(r);
    p.material.push_back(fragment ? 1 : 0);
    if (fragment) fragments.push_back(i);
  }
  crusher::FragmentOverlaps all;
  std::vector<bool> is_fragment(p.size(), false);
  for (const std::uint32_t f : fragments) is_fragment[f] = true;
  int touching = 0;
  for (const std::uint32_t f : fragments)
    for (std::uint32_t j = 0; j < p.size(); ++j) {
      if (j == f || (is_fragment[j] && j < f)) continue;
      const double overlap = p.radius[f] + p.radius[j] - (p.position[f] - p.position[j]).norm();
      if (!(overlap > 0)) continue;
      ++touching;
      all.max_fraction = std::max(all.max_fraction, overlap / std::min(p.radius[f], p.radius[j]));
      const double kf = model.materials[p.material[f]].kn, kj = model.materials[p.material[j]].kn;
      all.energy += 0.5 * kf * kj / (kf + kj) * overlap * overlap;
    }
  REQUIRE(touching > 50);
  const crusher::FragmentOverlaps grid = crusher::fragmentOverlaps(model, p, fragments);
  CHECK(grid.max_fraction == all.max_fraction);
  CHECK(grid.energy == all.energy);
  // The freeze's criteria read the largest through a cell grid (counting sort): the same, bit for bit
  // (twice: the buffers are kept).
  crusher::LargestOverlap largest;
  CHECK(largest(p, fragments) == all.max_fraction);
  CHECK(largest(p, fragments) == all.max_fraction);
  CHECK(largest(p, {}) == 0.0);
  // The freeze asks again as the balls move: shuffled by up to 1.4 mm a look, at the
  // seventh look the fragments moved 4 mm besides; the largest against every pair
  // each time, and a ball with no position (NaN) gives "no room".
  const auto everyPair = [&] {
    double worst = 0;
    for (const std::uint32_t f : fragments)
      for (std::uint32_t j = 0; j < p.size(); ++j) {
        const double overlap = p.radius[f] + p.radius[j] - (p.position[f] - p.position[j]).norm();
        if (j != f && overlap > 0) worst = std::max(worst, overlap / std::min(p.radius[f], p.radius[j]));
      }
    return worst;
  };
  for (int look = 0; look < 12; ++look) {
    for (geometry::Vec3& x : p.position)
      x += geometry::Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * 0.0008;
    if (look == 6)
      for (const std::uint32_t f : fragments) p.position[f].z() += 0.004 * (f % 60 == 0 ? 1 : -1);
    const double expected = everyPair();
    CHECK(largest(p, fragments) == expected);
  }
  p.position[fragments[0]].x() = std::numeric_limits<double>::quiet_NaN();
  CHECK(largest(p, fragments) == std::numeric_limits<double>::infinity());
  CHECK(crusher::fragmentOverlaps(model, p, {}).energy == 0.0);
}

TEST_CASE("a ball between two closing walls breaks when q exceeds its strength and not before, and the freeze parts the "
          "fragments without creating energy",
          "[crusher]") {
  std::unique_ptr<sim::World> world = pinchedBall(0.2);
  const BreakageSettings settings = pinchSettings();
  CrusherBreakage breakage(settings, 3);
  const ExperimentContext ctx{1, nullptr};
  breakage.start(*world);
  const double strength = settings.strength.strength(0.02, crusher::uniformFromId(3, 0));
  double q = 0;
  sim::Energy before;
  Vec3 parent_velocity;
  int steps = 0;
  double wall_force = 0;
  for (; steps < 20000; ++steps) {
    q = octahedral(*world, 0);
    wall_force = world->wallForces()[0].norm();
    parent_velocity = world->particles().velocity[0];
    if (breakage.check(world, ctx)) break;
    CHECK(q <= strength);  // not before
    before = energyAfterStep(world);
  }
  REQUIRE(breakage.events().size() == 1);
  const BreakageEvent& e = breakage.events().front();
  INFO("broke after " << steps << " steps at q = " << q << " Pa; the freeze took " << e.freeze_cycles << " cycles");
  CHECK(steps > 100);  // the walls had to close by ~10 um (0.2 m/s each, 0.15 us steps)
  CHECK(q > strength);
  CHECK(e.q == q);
  CHECK(e.strength == strength);
  CHECK(e.parent == 0);
  CHECK(e.fragments == std::vector<std::uint64_t>{1, 2, 3});  // new ids
  CHECK(e.freeze_cycles > 0);
  CHECK(e.freeze_end == crusher::FreezeEnd::Converged);  // free to part: the overlap criterion
  CHECK(e.freeze_overlap <= settings.freeze.overlap_fraction);
  CHECK_THAT(breakage.progress(), Contains("1 broken, freezes 1 converged 0 stalled"));
  // Two opposite point forces F: q = (2 sqrt 2 / pi) F / d^2 = 0.9 F / d^2 (Eq 6-12,
  // dem-models §11), the contact points a half overlap (4 um of 10 mm) inside.
  CHECK(q == Approx(2 * std::sqrt(2.0) / std::numbers::pi * wall_force / 4e-4).epsilon(1e-3));
  const sim::ParticleState& p = world->particles();
  REQUIRE(p.size() == 3);
  double mass = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    mass += p.mass[i];
    CHECK(p.velocity[i] == parent_velocity);  // the parent's velocity
    CHECK(p.omega[i] == Vec3::Zero());
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double overlap = p.radius[i] + p.radius[j] - (p.position[i] - p.position[j]).norm();
      CHECK(overlap <= settings.freeze.overlap_fraction * std::min(p.radius[i], p.radius[j]));  // apart
    }
    // The line of centres lies across the load (the minor direction is in the x-y plane).
    CHECK(std::abs(p.position[i].z()) < 1e-9);
  }
  CHECK(mass == Approx(2650 * 4.0 / 3.0 * std::numbers::pi * 1e-6).epsilon(1e-14));
  // The walls did not move during the freeze: the fragments' clock is the parent's.
  const double t_break = e.time;
  CHECK(world->time() == t_break);
  // No energy created: what the fragments have after the freeze (kinetic at the
  // parent's velocity, springs at their overlaps) is at most what the parent had.
  const sim::Energy after = energyAfterStep(world);
  INFO("before: kinetic " << before.kinetic_translational << " J, elastic " << before.elastic << " J; after: kinetic "
                          << after.kinetic_translational << " J, elastic " << after.elastic << " J");
  CHECK(before.elastic > 0);
  CHECK(after.kinetic_translational + after.kinetic_rotational + after.elastic <=
        before.kinetic_translational + before.kinetic_rotational + before.elastic);
}

TEST_CASE("a freeze that does not end within its cap keeps the breakage (break), defers it (defer) or stops the run "
          "with both criteria and the keys (stop)",
          "[crusher]") {
  using crusher::CrowdedOutcome;
  for (const CrowdedOutcome outcome : {CrowdedOutcome::Stop, CrowdedOutcome::Defer, CrowdedOutcome::Break}) {
    INFO("freeze_crowded = " << crusher::crowdedOutcomeName(outcome));
    std::unique_ptr<sim::World> world = pinchedBall(0.2);
    BreakageSettings settings = pinchSettings();
    settings.freeze.max_cycles = 5;  // the fragments need ~40
    settings.freeze.check_cycles = 1;
    settings.freeze.crowded = outcome;
    settings.crowded_bound = BreakageSettings::CrowdedBound::Overlap;
    settings.crowded_max_overlap = std::numeric_limits<double>::infinity();  // "break" keeps what 5 cycles leave
    settings.defer_time = 1e-4;  // s: the platens close 20 um in it
    CrusherBreakage breakage(settings, 3);
    const ExperimentContext ctx{1, nullptr};
    breakage.start(*world);
    std::string message;
    const sim::World* before = world.get();
    const double parent_mass = world->particles().mass[0];
    bool broke = false;
    try {
      for (int steps = 0; steps < 20000 && !(broke = breakage.check(world, ctx)); ++steps) {
        world->step();
        if (breakage.progress().find("deferred") != std::string::npos) break;
      }
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    if (outcome == CrowdedOutcome::Stop) {
      CHECK_THAT(message, Contains("freeze_max_cycles = 5") && Contains("freeze_max_contact_times") &&
                              Contains("freeze_overlap_fraction") && Contains("freeze_kinetic_fraction") &&
                              Contains("freeze_crowded"));
      continue;
    }
    CHECK(message.empty());
    if (outcome == CrowdedOutcome::Break) {
      // Kept: one event with the freeze's end "crowded", the fragments where the
      // freeze left them (still overlapping after 5 cycles) in a new World, the
      // parent's mass to round-off, and the overlap reported as a stalled one's.
      REQUIRE(broke);
      REQUIRE(breakage.events().size() == 1);
      const BreakageEvent& e = breakage.events().front();
      CHECK(e.freeze_end == crusher::FreezeEnd::Crowded);
      CHECK(e.freeze_cycles == 5);
      CHECK(e.freeze_overlap > settings.freeze.overlap_fraction);
      CHECK(e.freeze_contact_times > 0);
      const sim::ParticleState& p = world->particles();
      REQUIRE(p.size() == 3);
      double mass = 0, overlap = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        mass += p.mass[i];
        for (std::size_t j = i + 1; j < p.size(); ++j)
          overlap = std::max(overlap, (p.radius[i] + p.radius[j] - (p.position[i] - p.position[j]).norm()) /
                                          std::min(p.radius[i], p.radius[j]));
      }
      CHECK(mass == Approx(parent_mass).epsilon(1e-14));
      CHECK(overlap > 0);
      CHECK(overlap <= e.freeze_overlap * (1 + 1e-12));  // bounded by what the freeze reported
      CHECK_THAT(breakage.progress(), Contains("1 broken, freezes 0 converged 0 stalled 1 crowded"));
      const fs::path out = test::scratchDir("crusher-breakage-crowded");
      fs::create_directories(out);
      const nlohmann::json r = breakage.report({8, 16}, out);
      CHECK(r["freezes_crowded"] == 1);
      CHECK(r["freezes_converged"] == 0);
      CHECK(r["max_crowded_overlap_fraction"].get<double>() == e.freeze_overlap);
      CHECK(r["freeze_crowded"] == "break");
      CHECK(r["deferred"].empty());
      CHECK_THAT(test::slurp(out / "breakage.csv"), Contains(",crowded,"));
      fs::remove_all(out);
      continue;
    }
    // Deferred: no event, the ball whole in the same World, and it is not checked
    // again before defer_time has passed.
    CHECK_FALSE(broke);
    CHECK(breakage.events().empty());
    CHECK(world.get() == before);
    CHECK(world->particles().size() == 1);
    CHECK(world->particles().id[0] == 0);
    CHECK_THAT(breakage.progress(), Contains("(1 deferred)"));
    const double deferred_at = world->time();
    while (world->time() < deferred_at + 0.5 * settings.defer_time) {
      world->step();
      CHECK_FALSE(breakage.check(world, ctx));
    }
    CHECK(breakage.events().empty());
    CHECK_THAT(breakage.progress(), Contains("(1 deferred)"));
  }
}

TEST_CASE("a crowded freeze under break whose overlap is above freeze_crowded_max_overlap defers its parents, and "
          "defer_time 0 lets them break at the next check",
          "[crusher]") {
  std::unique_ptr<sim::World> world = pinchedBall(0.2);
  BreakageSettings settings = pinchSettings();
  settings.freeze.max_cycles = 5;  // cut before the fragments part: crowded at a large overlap
  settings.freeze.check_cycles = 1;
  settings.crowded_bound = BreakageSettings::CrowdedBound::Overlap;
  settings.crowded_max_overlap = 1e-3;
  settings.defer_time = 0;
  CrusherBreakage breakage(settings, 3);
  const ExperimentContext ctx{1, nullptr};
  breakage.start(*world);
  int steps = 0;
  while (steps < 20000 && breakage.progress().find("deferred") == std::string::npos) {
    CHECK_FALSE(breakage.check(world, ctx));
    world->step();
    ++steps;
  }
  REQUIRE_THAT(breakage.progress(), Contains("(1 deferred)"));
  CHECK(breakage.events().empty());
  CHECK(world->particles().size() == 1);
  // The next check (every step here) tries again: crowded again, deferred again.
  CHECK_FALSE(breakage.check(world, ctx));
  CHECK_THAT(breakage.progress(), Contains("(2 deferred)"));
  const fs::path out = test::scratchDir("crusher-breakage-crowded-bound");
  fs::create_directories(out);
  const nlohmann::json r = breakage.report({8, 16}, out);
  REQUIRE(r["deferred"].size() == 2);
  CHECK(r["deferred"][0]["overlap_fraction"].get<double>() > settings.crowded_max_overlap);
  fs::remove_all(out);
}

namespace {

/// One 20 mm ball at rest squeezed by `squeeze` (m) between two static planes
/// (no gravity, friction or damping: the run's mechanical energy is conserved
/// but for what a breakage changes).
std::unique_ptr<sim::World> squeezedBall(double squeeze) {
  std::unique_ptr<sim::World> pinched = pinchedBall(0.0);
  sim::Model m = pinched->model();
  m.walls[0].point.z() += squeeze;
  m.walls[1].point.z() -= squeeze;
  m.watchdog.max_overlap_fraction = std::numeric_limits<double>::infinity();  // crowded fragments overlap
  return std::make_unique<sim::World>(m, sim::WorldState(pinched->exportState()), 1);
}

/// Checks and steps `world` until a check breaks a ball or defers one; returns
/// whether it broke, with the run's energy after the step before that check.
bool untilBrokenOrDeferred(std::unique_ptr<sim::World>& world, CrusherBreakage& breakage, sim::Energy& before) {
  const ExperimentContext ctx{1, nullptr};
  for (int steps = 0; steps < 100; ++steps) {
    before = energyAfterStep(world);
    if (breakage.check(world, ctx)) return true;
    if (breakage.progress().find("deferred") != std::string::npos) return false;
  }
  FAIL("neither broken nor deferred in 100 steps");
  return false;
}

double mechanical(const sim::Energy& e) { return e.kinetic_translational + e.kinetic_rotational + e.elastic; }

}  // namespace

TEST_CASE("under freeze_crowded_bound = energy a crowded breakage is kept only when its fragments' overlaps hold no "
          "more elastic energy than the parent's contacts stored, and then the run's energy does not rise",
          "[crusher]") {
  BreakageSettings settings = pinchSettings();
  settings.strength.q_ref = 1e5;  // Pa: the lightest squeeze below breaks the ball at the first check
  // The fragments part after 40 cycles: cut at 39 the freeze is crowded with an
  // overlap of 0.0045 of the radius left (0.17 J at rock stiffness), 15 times the
  // old bound (freeze_crowded_max_overlap 3e-4).
  settings.freeze.max_cycles = 39;
  settings.freeze.check_cycles = 1;
  REQUIRE(settings.crowded_bound == BreakageSettings::CrowdedBound::Energy);  // the default
  const fs::path out = test::scratchDir("crusher-breakage-energy-bound");
  fs::create_directories(out);

  // A parent squeezed by 1 um stores ~1 mJ (two wall contacts at ~1e9 N/m): less
  // than what the fragments' overlaps after 39 cycles hold at rock stiffness.
  std::unique_ptr<sim::World> world = squeezedBall(1e-6);
  CrusherBreakage light(settings, 3);
  light.start(*world);
  const sim::World* light_world = nullptr;
  sim::Energy before;
  {
    const ExperimentContext ctx{1, nullptr};
    before = energyAfterStep(world);
    light_world = world.get();
    CHECK_FALSE(light.check(world, ctx));
  }
  REQUIRE_THAT(light.progress(), Contains("(1 deferred)"));
  CHECK(light.events().empty());
  CHECK(world.get() == light_world);  // the run's World as it was, the ball whole
  CHECK(world->particles().size() == 1);
  const nlohmann::json deferred = light.report({8, 16}, out)["deferred"];
  REQUIRE(deferred.size() == 1);
  const double parent_light = deferred[0]["parent_energy_J"].get<double>();
  const double handed_back = deferred[0]["handed_back_energy_J"].get<double>();
  INFO("parent " << parent_light << " J, fragments' overlaps " << handed_back << " J, overlap "
                 << deferred[0]["overlap_fraction"].get<double>());
  // The parent's energy is its two wall springs', as the run's energy log has them.
  CHECK(parent_light == Approx(before.elastic).epsilon(1e-6));
  CHECK(handed_back > parent_light);

  // The same freeze (the fragments do not reach the planes) after a squeeze that
  // stores 4 times what the fragments will hold (elastic energy ~ squeeze^2): kept.
  const double squeeze = 1e-6 * std::sqrt(4 * handed_back / parent_light);
  INFO("squeeze " << squeeze << " m");
  REQUIRE(squeeze < 0.1 * 0.01);  // the 60 % fragment (0.843 R) stays clear of the planes
  world = squeezedBall(squeeze);
  CrusherBreakage heavy(settings, 3);
  heavy.start(*world);
  REQUIRE(untilBrokenOrDeferred(world, heavy, before));
  REQUIRE(heavy.events().size() == 1);
  const BreakageEvent& e = heavy.events().front();
  CHECK(e.freeze_end == crusher::FreezeEnd::Crowded);
  CHECK(e.freeze_cycles == 39);
  CHECK(e.parent_energy == Approx(before.elastic).epsilon(1e-6));
  CHECK(e.handed_back_energy == Approx(handed_back).epsilon(1e-6));
  CHECK(e.handed_back_energy <= e.parent_energy);
  // The old rule would have deferred it: the overlap is far above 3e-4 of the radius.
  CHECK(e.freeze_overlap > 10 * BreakageSettings{}.crowded_max_overlap);
  // The run's mechanical energy (kinetic + elastic) does not rise: right after the
  // breakage it is what the fragments' overlaps hold (the handed-back energy) and
  // below what the parent had; no damping, so it stays there to the integrator's
  // error (1 %) while the fragments fly apart.
  sim::Energy after = energyAfterStep(world);
  INFO("before " << mechanical(before) << " J, after " << mechanical(after) << " J");
  CHECK(after.elastic + after.kinetic_translational + after.kinetic_rotational ==
        Approx(e.handed_back_energy).epsilon(1e-2));
  CHECK(mechanical(after) <= mechanical(before));
  double highest = mechanical(after);
  for (int steps = 0; steps < 2000; ++steps) highest = std::max(highest, mechanical(energyAfterStep(world)));
  CHECK(highest <= e.handed_back_energy * 1.01);
  CHECK(highest < mechanical(before));
  const nlohmann::json r = heavy.report({8, 16}, out);
  CHECK(r["freeze_crowded_bound"] == "energy");
  CHECK(r["freeze_crowded_energy_factor"] == 1.0);
  CHECK(r["max_crowded_handed_back_energy_J"].get<double>() == e.handed_back_energy);
  CHECK(r["max_handed_back_excess_J"].get<double>() <= 0);
  CHECK_THAT(test::slurp(out / "breakage.csv"), Contains("parent_energy_J,handed_back_energy_J"));

  // With the factor below the ratio the same breakage waits.
  settings.crowded_energy_factor = 0.5 * e.handed_back_energy / e.parent_energy;
  world = squeezedBall(squeeze);
  CrusherBreakage strict(settings, 3);
  strict.start(*world);
  CHECK_FALSE(untilBrokenOrDeferred(world, strict, before));
  CHECK(strict.events().empty());
  fs::remove_all(out);
}

namespace {

/// Two 10 mm fragments overlapping by `start` (m) in a row along x with an
/// unbroken 10 mm rock ball touching the second: the rock ball's stiffness at the
/// freeze's huge density sets the freeze's step, so the fragments move on a time
/// scale thousands of cycles long, as in the crusher. With `keep` (m): two held
/// planes, one touching the ball, the other as far as makes the pair keep that
/// overlap at rest: the chain wall-A-B-ball-wall (soft springs 1e3, 500 and 1e3
/// N/m; the ball's stiff) is 6 radii long unloaded and the pair takes half of
/// what the walls take off it.
struct FreezeCase {
  sim::Model model;
  sim::WorldState state;
};

FreezeCase fragmentRow(double start, std::optional<double> keep) {
  sim::Model m;
  m.materials.push_back({"rock", 2650, 1e9, 1e9, 0.0});
  m.materials.push_back({"steel", 7800, 1e13, 1e13, 0.0});
  m.gravity = Vec3::Zero();
  m.watchdog.max_overlap_fraction = std::numeric_limits<double>::infinity();  // the fragments overlap by design
  const double r = 0.005, b = r - start / 2, c = b + 2 * r;
  if (keep) {
    sim::Wall right;
    right.name = "right";
    right.point = Vec3(c + r, 0, 0);
    right.normal = -Vec3::UnitX();
    right.material = 1;
    sim::Wall left = right;
    left.name = "left";
    left.point = Vec3(c + r - (6 * r - 2 * *keep), 0, 0);
    left.normal = Vec3::UnitX();
    m.walls = {left, right};
  }
  std::vector<sim::SphereSpec> balls(3);
  balls[0].position = Vec3(-b, 0, 0);
  balls[1].position = Vec3(b, 0, 0);
  balls[2].position = Vec3(c, 0, 0);
  for (auto& ball : balls) ball.radius = r;
  sim::World world(m, balls, 1);
  return {m, world.exportState()};
}

}  // namespace

TEST_CASE("a freeze whose fragments are pinched between held walls ends as stalled with the overlap they keep, and free "
          "fragments still converge",
          "[crusher]") {
  for (const crusher::FreezeScope scope :
       {crusher::FreezeScope::Local, crusher::FreezeScope::All}) {
    INFO("scope " << crusher::freezeScopeName(scope));
    crusher::FreezeSettings settings;  // the defaults
    settings.scope = scope;
    settings.stall_max_overlap = 0.01;  // the pinched row keeps 0.005 (the default 3e-4 would call it crowded)
    const std::vector<std::uint32_t> fragments{0, 1};
    // Snug: 0.1 mm (0.02 of the radius) at the split, 25 um (0.005) kept, within
    // freeze_stall_max_overlap. (Parting from a deeper overlap the pair swings past
    // its rest and is apart for a moment, which ends the freeze as converged.)
    FreezeCase pinched = fragmentRow(1e-4, 25e-6);
    const crusher::FreezeResult stalled =
        crusher::freezeFragments(pinched.model, pinched.state, fragments, settings, 1);
    INFO("pinched: " << stalled.cycles << " cycles of " << stalled.dt << " s, window "
                     << stalled.stall_window_cycles << " cycles, overlap " << stalled.max_overlap
                     << ", kinetic " << stalled.kinetic_energy << " of "
                     << stalled.artificial_energy << " J");
    CHECK(stalled.end == crusher::FreezeEnd::Stalled);
    CHECK(std::string(crusher::freezeEndName(stalled.end)) == "stalled");
    // What the walls allow (0.005), nearly: the last approach to rest under local
    // damping is a creep (the damped force is 0.1 of a spring force that vanishes at
    // rest) slower than 1 % per window, so the rule ends it a little above.
    CHECK(stalled.max_overlap >= 0.005 * 0.999);
    CHECK(stalled.max_overlap < 0.005 * 1.25);
    CHECK(stalled.kinetic_energy <= settings.kinetic_fraction * stalled.artificial_energy);
    // The window is the fragments' time: with every ball in, thousands of the rock
    // ball's steps, not a handful of cycles.
    if (scope == crusher::FreezeScope::All) CHECK(stalled.stall_window_cycles > 1000);
    CHECK(stalled.cycles < 6 * stalled.stall_window_cycles);  // a few windows, not the cap
    CHECK(stalled.cycles < static_cast<std::uint64_t>(settings.max_cycles) / 20);
    const sim::ParticleState& p = pinched.state.particles;
    CHECK(2 * p.radius[0] - (p.position[1] - p.position[0]).norm() ==
          Approx(stalled.max_overlap * 0.005));  // kept

    // The same row without the walls: the pair pushes itself and the ball apart and
    // meets the overlap criterion (the stall rule must not end it while the fragments
    // are still getting under way).
    FreezeCase free = fragmentRow(2e-3, std::nullopt);
    const crusher::FreezeResult converged =
        crusher::freezeFragments(free.model, free.state, fragments, settings, 1);
    INFO("free: " << converged.cycles << " cycles, overlap " << converged.max_overlap);
    CHECK(converged.end == crusher::FreezeEnd::Converged);
    CHECK(converged.max_overlap <= settings.overlap_fraction);

    // Tight: 2 mm (0.4) at the split, 1.25 mm (0.25) kept, above
    // freeze_stall_max_overlap: no stall, the freeze runs into freeze_max_cycles;
    // with the bound raised it stalls there.
    crusher::FreezeSettings capped = settings;
    capped.max_cycles = static_cast<std::int64_t>(4 * stalled.cycles);
    FreezeCase tight = fragmentRow(2e-3, 1.25e-3);
    // Such a freeze is crowded: with "defer" it ends so, the state as it was;
    const std::vector<Vec3> tight_start = tight.state.particles.position;
    capped.crowded = crusher::CrowdedOutcome::Defer;
    const crusher::FreezeResult crowded =
        crusher::freezeFragments(tight.model, tight.state, fragments, capped, 1);
    CHECK(crowded.end == crusher::FreezeEnd::Crowded);
    CHECK(crowded.cycles == static_cast<std::uint64_t>(capped.max_cycles));
    CHECK(tight.state.particles.position == tight_start);
    // with "break" (the default) the fragments come back where it left them, at the
    // overlap it reports;
    capped.crowded = crusher::CrowdedOutcome::Break;
    const crusher::FreezeResult kept = crusher::freezeFragments(tight.model, tight.state, fragments, capped, 1);
    CHECK(kept.end == crusher::FreezeEnd::Crowded);
    CHECK(kept.cycles == crowded.cycles);
    CHECK(kept.max_overlap == crowded.max_overlap);
    CHECK(tight.state.particles.position != tight_start);
    const sim::ParticleState& t = tight.state.particles;
    CHECK(2 * t.radius[0] - (t.position[1] - t.position[0]).norm() == Approx(kept.max_overlap * 0.005));
    tight = fragmentRow(2e-3, 1.25e-3);
    capped.crowded = crusher::CrowdedOutcome::Stop;  // or the run stops, naming the settings
    CHECK_THROWS_WITH(crusher::freezeFragments(tight.model, tight.state, fragments, capped, 1),
                      Contains("freeze_max_cycles") && Contains("freeze_stall_max_overlap = 0.01"));
    capped.stall_max_overlap = 0.3;
    tight = fragmentRow(2e-3, 1.25e-3);
    const crusher::FreezeResult deep =
        crusher::freezeFragments(tight.model, tight.state, fragments, capped, 1);
    CHECK(deep.end == crusher::FreezeEnd::Stalled);
    CHECK(deep.max_overlap > 0.2);
    // At about the rest overlap: with every ball in, within 0.1 %; in the local
    // freeze, whose step is a quarter of the fragments' time scale, the creep under
    // local damping is slower per window and the rule ends it a few % above.
    CHECK(deep.max_overlap <= 0.25 * 1.1);

    // Without the stall rule the snug row runs into freeze_max_cycles, as before.
    crusher::FreezeSettings no_stall = settings;
    no_stall.stall_window = 0;
    no_stall.max_cycles = static_cast<std::int64_t>(3 * stalled.cycles);
    no_stall.crowded = crusher::CrowdedOutcome::Stop;
    FreezeCase again = fragmentRow(1e-4, 25e-6);
    CHECK_THROWS_WITH(crusher::freezeFragments(again.model, again.state, fragments, no_stall, 1),
                      Contains("freeze_max_cycles") && Contains("freeze_stall_window = 0"));
  }
}

TEST_CASE("the crowded cap in contact times ends a freeze that cannot part long before freeze_max_cycles, which "
          "stays its upper bound",
          "[crusher]") {
  // The tight row: pinched at 0.25 of the radius, above freeze_stall_max_overlap,
  // it cannot part and does not stall.
  const std::vector<std::uint32_t> fragments{0, 1};
  crusher::FreezeSettings settings;  // the defaults: 100 contact times, at most 1e6 cycles, "break"
  FreezeCase tight = fragmentRow(2e-3, 1.25e-3);
  const crusher::FreezeResult capped = crusher::freezeFragments(tight.model, tight.state, fragments, settings, 1);
  // A 10 mm fragment at 3e9 kg/m^3 on 1e3 N/m: pi sqrt(m/k) = 3.94 s.
  const double contact_time = std::numbers::pi * std::sqrt(3e9 * 4.0 / 3.0 * std::numbers::pi * 1.25e-7 / 1e3);
  INFO("capped: " << capped.cycles << " cycles of " << capped.dt << " s, cap " << capped.cap_cycles << ", overlap "
                  << capped.max_overlap);
  CHECK(capped.contact_time == Approx(contact_time).epsilon(1e-12));
  CHECK(capped.cap_cycles == static_cast<std::uint64_t>(std::ceil(100 * contact_time / capped.dt)));
  CHECK(capped.end == crusher::FreezeEnd::Crowded);
  CHECK(capped.cycles >= capped.cap_cycles);
  CHECK(capped.cycles < capped.cap_cycles + static_cast<std::uint64_t>(settings.check_cycles));
  CHECK(capped.cycles < static_cast<std::uint64_t>(settings.max_cycles) / 100);
  CHECK(capped.max_overlap > settings.stall_max_overlap);  // jammed, not slow
  CHECK_FALSE(capped.jammed);  // the jam rule is off by default

  // The jam rule ends it sooner: at rest, its overlap no longer falling, after its
  // window of 20 contact times and well before the cap, at the overlap the cap
  // would have left (the fragments have not moved since).
  crusher::FreezeSettings jam = settings;
  jam.jam_contact_times = 20;
  tight = fragmentRow(2e-3, 1.25e-3);
  const crusher::FreezeResult jammed = crusher::freezeFragments(tight.model, tight.state, fragments, jam, 1);
  INFO("jammed: " << jammed.cycles << " cycles, window " << jammed.jam_window_cycles << ", overlap "
                  << jammed.max_overlap);
  CHECK(jammed.end == crusher::FreezeEnd::Crowded);
  CHECK(jammed.jammed);
  CHECK(jammed.jam_window_cycles == static_cast<std::uint64_t>(std::ceil(20 * contact_time / jammed.dt)));
  CHECK(jammed.cycles >= jammed.jam_window_cycles);
  CHECK(jammed.cycles < capped.cap_cycles / 2);
  CHECK(jammed.max_overlap == Approx(capped.max_overlap).epsilon(0.01));
  // A freeze that can part still does with the rule on: the free row converges in
  // the same cycles as without it.
  FreezeCase free = fragmentRow(2e-3, std::nullopt);
  FreezeCase free_again = fragmentRow(2e-3, std::nullopt);
  const crusher::FreezeResult parted = crusher::freezeFragments(free.model, free.state, fragments, jam, 1);
  const crusher::FreezeResult parted_off =
      crusher::freezeFragments(free_again.model, free_again.state, fragments, settings, 1);
  CHECK(parted.end == crusher::FreezeEnd::Converged);
  CHECK(parted.cycles == parted_off.cycles);
  CHECK(free.state.particles.position == free_again.state.particles.position);

  // Without it the same freeze runs into freeze_max_cycles (here 3 times the cap).
  crusher::FreezeSettings cycles_only = settings;
  cycles_only.max_contact_times = 0;
  cycles_only.max_cycles = static_cast<std::int64_t>(3 * capped.cap_cycles);
  tight = fragmentRow(2e-3, 1.25e-3);
  const crusher::FreezeResult long_run = crusher::freezeFragments(tight.model, tight.state, fragments, cycles_only, 1);
  CHECK(long_run.end == crusher::FreezeEnd::Crowded);
  CHECK(long_run.cap_cycles == static_cast<std::uint64_t>(cycles_only.max_cycles));
  CHECK(long_run.cycles >= 3 * capped.cap_cycles);

  // With every ball in, the rock ball sets the step: 100 contact times are millions
  // of cycles, and freeze_max_cycles binds.
  crusher::FreezeSettings all = settings;
  all.scope = crusher::FreezeScope::All;
  all.max_cycles = 50000;
  tight = fragmentRow(2e-3, 1.25e-3);
  const crusher::FreezeResult bounded = crusher::freezeFragments(tight.model, tight.state, fragments, all, 1);
  CHECK(bounded.end == crusher::FreezeEnd::Crowded);
  CHECK(bounded.cap_cycles == 50000);
  CHECK(100 * bounded.contact_time / bounded.dt > 1e6);
}

TEST_CASE(
    "a local freeze holds the balls near the fragments still, leaves the others out, steps at the "
    "fragments' own "
    "pace, and widens its reach when a fragment travels beyond it",
    "[crusher]") {
  const std::vector<std::uint32_t> fragments{0, 1};
  crusher::FreezeSettings all;
  all.scope = crusher::FreezeScope::All;
  const crusher::FreezeSettings local;  // the default
  REQUIRE(local.scope == crusher::FreezeScope::Local);
  FreezeCase a = fragmentRow(2e-3, std::nullopt), l = fragmentRow(2e-3, std::nullopt);
  const crusher::FreezeResult ra = crusher::freezeFragments(a.model, a.state, fragments, all, 1);
  const crusher::FreezeResult rl = crusher::freezeFragments(l.model, l.state, fragments, local, 1);
  INFO("all: " << ra.cycles << " cycles of " << ra.dt << " s; local: " << rl.cycles << " cycles of "
               << rl.dt << " s");
  CHECK(ra.end == crusher::FreezeEnd::Converged);
  CHECK(rl.end == crusher::FreezeEnd::Converged);
  CHECK(ra.balls == 3);
  CHECK(rl.balls == 3);  // the rock ball touches a fragment: within the reach
  // Held, the rock ball has not moved by a bit; with every ball in it was pushed.
  const Vec3 rock_start = fragmentRow(2e-3, std::nullopt).state.particles.position[2];
  CHECK(l.state.particles.position[2] == rock_start);
  CHECK(a.state.particles.position[2] != rock_start);
  // The step is no longer the rock ball's at the huge density but the fragments'
  // (k 1e3 against 1e9 N/m at equal masses: sqrt(1e6) = 1000 times longer).
  CHECK(rl.dt > 100 * ra.dt);
  CHECK(rl.cycles * 50 < ra.cycles);
  // The fragments parted in both (overlap criterion met).
  for (const FreezeCase* c : {&a, &l}) {
    const sim::ParticleState& p = c->state.particles;
    CHECK(2 * p.radius[0] - (p.position[1] - p.position[0]).norm() <=
          local.overlap_fraction * p.radius[0]);
  }

  // A ball to the left of fragment 0, 0.5 mm from it: the fragment travels ~1 mm
  // left. With a reach of 0.01 diameters (0.1 mm) the ball is out of the first
  // freeze, which the fragment ends inside it: the reach doubles to 0.2, 0.4 and
  // 0.8 mm, which takes it in. With the default reach (10 mm) it is in at once, and
  // 50 mm away it is never in.
  const auto withBallLeft = [](double gap) {
    FreezeCase c = fragmentRow(2e-3, std::nullopt);
    sim::ParticleState& p = c.state.particles;
    p.position[2] =
        p.position[0] - Vec3(2 * p.radius[0] + gap, 0, 0);  // the rock ball moved to the left
    return c;
  };
  crusher::FreezeSettings short_reach = local;
  short_reach.local_reach = 0.01;
  FreezeCase near = withBallLeft(0.5e-3);
  const crusher::FreezeResult widened =
      crusher::freezeFragments(near.model, near.state, fragments, short_reach, 1);
  INFO("widened: " << widened.reach_widenings << " widenings, " << widened.balls << " balls, "
                   << widened.cycles << " cycles, end " << crusher::freezeEndName(widened.end));
  CHECK(widened.reach_widenings == 3);
  CHECK(widened.balls == 3);
  CHECK(widened.end == crusher::FreezeEnd::Converged);
  const sim::ParticleState& pn = near.state.particles;
  CHECK((pn.position[0] - pn.position[2]).norm() >=
        2 * pn.radius[0] * (1 - local.overlap_fraction));  // not inside it
  FreezeCase in_reach = withBallLeft(0.5e-3);
  const crusher::FreezeResult at_once =
      crusher::freezeFragments(in_reach.model, in_reach.state, fragments, local, 1);
  CHECK(at_once.reach_widenings == 0);
  CHECK(at_once.balls == 3);
  FreezeCase far = withBallLeft(50e-3);
  const crusher::FreezeResult alone =
      crusher::freezeFragments(far.model, far.state, fragments, local, 1);
  CHECK(alone.reach_widenings == 0);
  CHECK(alone.balls == 2);
  CHECK(alone.end == crusher::FreezeEnd::Converged);
}

TEST_CASE("a local freeze moves the neighbours that bore no load like fragments and holds the loaded ones, "
          "World::touchingContacts tells them apart",
          "[crusher]") {
  const std::vector<std::uint32_t> fragments{0, 1};
  const crusher::FreezeSettings local;
  // The tight row: the fragments overlap each other and fragment 0 the left wall
  // (by 0.5 mm); the rock ball only just meets fragment 1 (no overlap: not
  // touching). Before the first step of a World from a saved state, those its
  // positions overlap: the same.
  FreezeCase tight = fragmentRow(2e-3, 1.25e-3);
  sim::World world(tight.model, tight.state, 1);
  using Pair = std::pair<std::uint32_t, std::uint32_t>;
  const sim::TouchingContacts unstepped = world.touchingContacts();
  world.step();
  const sim::TouchingContacts t = world.touchingContacts();
  CHECK(t.pairs == std::vector<Pair>{{0, 1}});
  CHECK(unstepped.pairs == t.pairs);
  CHECK(unstepped.walls == t.walls);
  CHECK(unstepped.pair_energy[0] == Approx(0.5 * 5e8 * 2e-3 * 2e-3));  // 1e9 N/m twice in series, 2 mm
  CHECK(std::count(t.walls.begin(), t.walls.end(), Pair{0, 0}) == 1);
  CHECK(std::none_of(t.walls.begin(), t.walls.end(), [](const Pair& c) { return c.first == 1; }));

  // The free row: the rock ball touches only fragment 1 (its parent's place). Loose,
  // it is pushed aside with the fragments; loaded (say it touched another ball), it
  // is held where it was.
  const Vec3 rock_start = fragmentRow(2e-3, std::nullopt).state.particles.position[2];
  FreezeCase loose = fragmentRow(2e-3, std::nullopt), loaded = fragmentRow(2e-3, std::nullopt);
  const crusher::FreezeResult rl =
      crusher::freezeFragments(loose.model, loose.state, fragments, local, 1, {false, false, false});
  const crusher::FreezeResult rh =
      crusher::freezeFragments(loaded.model, loaded.state, fragments, local, 1, {false, false, true});
  INFO("loose: " << rl.cycles << " cycles, loaded: " << rh.cycles << " cycles");
  CHECK(rl.end == crusher::FreezeEnd::Converged);
  CHECK(rh.end == crusher::FreezeEnd::Converged);
  CHECK(rl.moved_neighbours == 1);
  CHECK(rh.moved_neighbours == 0);
  CHECK(loose.state.particles.position[2].x() > rock_start.x());  // pushed along +x, away from the pair
  CHECK(loaded.state.particles.position[2] == rock_start);
  // Parted: no mover overlaps anything beyond the criterion.
  const sim::ParticleState& p = loose.state.particles;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = i + 1; j < 3; ++j)
      CHECK(2 * p.radius[0] - (p.position[i] - p.position[j]).norm() <= local.overlap_fraction * p.radius[0]);
  // One flag per ball, or none.
  FreezeCase bad = fragmentRow(2e-3, std::nullopt);
  CHECK_THROWS_WITH(crusher::freezeFragments(bad.model, bad.state, fragments, local, 1, {false}),
                    Contains("one `loaded` flag per ball"));
}

TEST_CASE("a stop request during a freeze ends it at once and leaves the state as it was before the breakage",
          "[crusher]") {
  // Ctrl-C or SIGTERM in a long freeze (up to 1e6 cycles) must not wait for it:
  // the run stops with the state before the breakage, which a restart breaks again.
  FreezeCase row = fragmentRow(2e-3, std::nullopt);
  const std::vector<Vec3> before = row.state.particles.position;
  rocklab::experiments::requestStop();
  const crusher::FreezeResult r = crusher::freezeFragments(row.model, row.state, {0, 1}, crusher::FreezeSettings{}, 1);
  rocklab::experiments::clearStopRequest();
  CHECK(r.end == crusher::FreezeEnd::Interrupted);
  CHECK(r.cycles == 0);
  CHECK(row.state.particles.position == before);
  CHECK(std::string(crusher::freezeEndName(r.end)) == "interrupted");
}

TEST_CASE("breakage settings: off by default, keys checked by name, and a step too long for the smallest fragment "
          "stops the run as bad input",
          "[scene][crusher]") {
  const std::string scene = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/cone-crusher-pbm.toml";
  CHECK(!settingsOf<CrusherRunSettings>(loadScene(scene)).breakage.enabled);
  const Scene on = loadScene(scene, {"experiment.breakage.mode=\"equal\""});
  const BreakageSettings& b = settingsOf<CrusherRunSettings>(on).breakage;
  CHECK(b.enabled);
  CHECK(b.mode == crusher::SplitMode::Equal);
  CHECK(b.offsets == crusher::defaultOffsets(crusher::SplitMode::Equal));
  CHECK(b.strength.q_ref == 25.2e6);
  CHECK(b.min_diameter == 0.004);
  const auto error = [&](const std::string& assignment) {
    try {
      loadScene(scene, {assignment});
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("loaded");
  };
  CHECK_THAT(error("experiment.breakage.mode=\"quad\""), Contains("experiment.breakage.mode"));
  CHECK_THAT(error("experiment.breakage.offsets=[0.5,0]"), Contains("experiment.breakage.offsets") && Contains("needs 3"));
  CHECK_THAT(error("experiment.breakage.freeze_local_damping=1.5"), Contains("freeze_local_damping"));
  CHECK_THAT(error("experiment.breakage.freeze_stall_tolerance=1"),
             Contains("experiment.breakage.freeze_stall_tolerance") && Contains("[0, 1)"));
  CHECK_THAT(error("experiment.breakage.freeze_stall_window=-1"), Contains("experiment.breakage.freeze_stall_window"));
  CHECK_THAT(error("experiment.breakage.q_reff=1"), Contains("q_reff"));
  CHECK_THAT(error("experiment.breakage.freeze_scope=\"near\""),
             Contains("experiment.breakage.freeze_scope") && Contains("\"local\""));
  CHECK_THAT(error("experiment.breakage.freeze_local_reach=0"),
             Contains("experiment.breakage.freeze_local_reach"));
  CHECK_THAT(error("experiment.breakage.freeze_held_density=-1"),
             Contains("experiment.breakage.freeze_held_density"));
  // The boolean freeze_defer_crowded was replaced: a scene that has it is told the new key.
  CHECK_THAT(error("experiment.breakage.freeze_defer_crowded=true"),
             Contains("experiment.breakage.freeze_defer_crowded") && Contains("freeze_crowded") &&
                 Contains("\"defer\""));
  CHECK_THAT(error("experiment.breakage.freeze_crowded=\"wait\""),
             Contains("experiment.breakage.freeze_crowded") && Contains("\"break\""));
  CHECK_THAT(error("experiment.breakage.freeze_max_contact_times=-1"),
             Contains("experiment.breakage.freeze_max_contact_times"));
  CHECK(b.freeze.crowded == crusher::CrowdedOutcome::Break);
  CHECK(b.crowded_bound == BreakageSettings::CrowdedBound::Energy);
  CHECK(b.crowded_energy_factor == 1.0);
  CHECK(settingsOf<CrusherRunSettings>(loadScene(scene, {"experiment.breakage.freeze_crowded_bound=\"overlap\""}))
            .breakage.crowded_bound == BreakageSettings::CrowdedBound::Overlap);
  CHECK_THAT(error("experiment.breakage.freeze_crowded_bound=\"joules\""),
             Contains("experiment.breakage.freeze_crowded_bound") && Contains("\"energy\"") &&
                 Contains("\"overlap\""));
  CHECK_THAT(error("experiment.breakage.freeze_crowded_energy_factor=-1"),
             Contains("experiment.breakage.freeze_crowded_energy_factor"));
  CHECK(settingsOf<CrusherRunSettings>(loadScene(scene, {"experiment.breakage.freeze_crowded=\"defer\""}))
            .breakage.freeze.crowded == crusher::CrowdedOutcome::Defer);
  CHECK(
      settingsOf<CrusherRunSettings>(loadScene(scene, {"experiment.breakage.freeze_scope=\"all\""}))
          .breakage.freeze.scope == crusher::FreezeScope::All);
  CHECK(b.freeze.scope == crusher::FreezeScope::Local);

  // The tiny run's step (soft contacts) is too long for a 1.9 mm fragment at 70 GPa.
  const fs::path out = test::scratchDir("crusher-breakage-dt");
  auto args = test::tinyCrusherRunArgs(out.string());
  args.insert(args.end(), {"--set", "experiment.breakage.mode=\"triple\""});
  std::string log;
  CHECK(test::cliLogged(args, log) == 2);
  CHECK_THAT(log, Contains("smallest fragment") && Contains("timestep.dt") &&
                      Contains("experiment.breakage.min_diameter"));
  CHECK_THAT(log, Contains("experiment \"crusher\": "));  // whose settings, not "phase switch"
  // The same with the step set by the scene (allowed for its balls): the breakage's
  // message, not the engine's audit naming only timestep.dt.
  args.insert(args.end(), {"--set", "timestep.dt=1e-6", "--overwrite"});
  log.clear();
  CHECK(test::cliLogged(args, log) == 2);
  CHECK_THAT(log, Contains("smallest fragment") && Contains("experiment.breakage.min_diameter"));
  fs::remove_all(out);
}

TEST_CASE("a tiny crusher run with breakage: balls break, the fragments are discharged, no mass is lost, and one "
          "thread or two give the same events",
          "[cli][crusher]") {
  // Weak balls (0.2 MPa at 21 mm) checked every 20 us break on their impacts in the
  // chamber; min_diameter 7.9 mm lets each feed ball break once; soft fragments
  // (youngs_modulus 1e8 Pa) and dt 0.7 us hold the smallest fragment. The balls
  // break by t = 0.17 s: the two-thread run stops at 0.25 s (its events must be
  // the same), the one-thread run goes on until the chamber is empty. (A world this
  // small steps on one thread whatever is asked: what the second run guards is the
  // driver, whose draws and order must not depend on the thread setting.)
  std::string first_events;
  for (const int threads : {1, 2}) {
    const fs::path out = test::scratchDir("crusher-breakage-run-" + std::to_string(threads));
    // The scene with the breakage on (its dt and minimum size overridden below).
    auto args = test::tinyCrusherRunArgs(out.string(), threads, "cone-crusher-pbm-breakage.toml");
    for (const char* set : {"experiment.breakage.q_ref=2e5", "experiment.breakage.check_interval=2e-5",
                            "experiment.breakage.youngs_modulus=1e8", "experiment.breakage.min_diameter=0.0079",
                            "timestep.dt=7e-7", "output.vtk=false"})
      args.insert(args.end(), {"--set", set});
    if (threads == 2) args.insert(args.end(), {"--set", "scene.end_time=0.25"});
    REQUIRE(test::cli(args) == 0);
    std::ifstream in(out / "results.json");
    const auto r = nlohmann::json::parse(in);
    const auto& c = r["crusher"];
    INFO(c.dump());
    const auto& b = c["breakage"];
    CHECK(b["events"].get<int>() >= 1);
    CHECK(b["fragments_created"] == 3 * b["events"].get<int>());
    // The breakage's cost is part of the stepping's wall time: checks and freezes.
    const auto& w = r["wall_time_s"];
    CHECK(w["breakage_checks"].get<double>() > 0);
    CHECK(w["breakage_freezes"].get<double>() > 0);
    CHECK(w["breakage_checks"].get<double>() + w["breakage_freezes"].get<double>() < w["stepping"].get<double>());
    // The particle count: six fed, each breakage adds two (three fragments for a ball).
    CHECK(c["balls_max"].get<int>() >= 6);
    CHECK(c["balls_max"].get<int>() <= 6 + 2 * b["events"].get<int>());
    CHECK(fs::exists(out / "ball_count.png"));
    if (threads == 1) {
      CHECK(c["discharged_balls"] == 6 + 2 * b["events"].get<int>());
      CHECK(c["empty"] == true);
      CHECK(c["psd"][2]["passing"].get<double>() > 0);  // fragments finer than 5.6 mm in the product
      // The product is finer than the feed on every sieve (breakage only makes balls smaller).
      for (std::size_t k = 0; k < c["psd"].size(); ++k)
        CHECK(c["psd"][k]["passing"].get<double>() >= c["feed_psd"][k]["passing"].get<double>());
      CHECK(c["feed_psd"][2]["passing"] == 0.0);  // the feed (8-9 mm) has nothing finer than 5.6 mm
      // Whiten's model fed with the run's own selection and breakage matrix gives
      // back its product (the chamber is empty): the bookkeeping balances.
      CHECK(c["whiten"]["from_run"]["largest_difference_from_product"].get<double>() < 1e-12);
      CHECK(c["whiten"]["from_parameters"]["mass_balance_relative"].get<double>() == Approx(0.0).margin(1e-14));
      CHECK(c["breakages"] == b["events"]);
    }
    const auto& balance = b["mass_balance"];
    CHECK(balance["feed_kg"].get<double>() ==
          Approx(balance["product_kg"].get<double>() + balance["in_chamber_kg"].get<double>()).epsilon(1e-14));
    CHECK(b["freezes_converged"].get<int>() + b["freezes_stalled"].get<int>() + b["freezes_crowded"].get<int>() ==
          b["freezes"].get<int>());
    CHECK(b["max_freeze_overlap_fraction"].get<double>() >= 0);
    CHECK(b["freeze_scope"] == "local");
    CHECK(b["max_freeze_balls"].get<int>() >= 3);  // at least the three fragments
    const std::string events = test::slurp(out / "breakage.csv");
    CHECK(std::count(events.begin(), events.end(), '\n') == 1 + b["events"].get<int>());
    CHECK_THAT(events, Contains("freeze_cycles,freeze_end,freeze_overlap_fraction,freeze_contact_times,kinetic_jump_J,"
                                "parent_energy_J,handed_back_energy_J\n"));
    if (threads == 1)
      first_events = events;
    else
      CHECK(events == first_events);
    fs::remove_all(out);
  }
}

TEST_CASE("breakage start: \"feed\" breaks weak balls on the stop wall, \"release\" checks from the stop wall's "
          "removal on",
          "[cli][crusher]") {
  // Balls of 2 kPa strength break at their first impact. The stop wall goes at
  // 0.15 s: under "feed" (the default) they break in the bin on it, under "release"
  // no check is made before 0.15 s and they break in the chamber.
  double first_feed = 0, first_release = 0;
  for (const std::string start : {"feed", "release"}) {
    const fs::path out = test::scratchDir("crusher-breakage-start-" + start);
    auto args = test::tinyCrusherRunArgs(out.string(), 1, "cone-crusher-pbm-breakage.toml");
    for (const std::string& set : std::vector<std::string>{"experiment.breakage.q_ref=2e3", "experiment.breakage.check_interval=2e-5",
                                  "experiment.breakage.youngs_modulus=1e8", "experiment.breakage.min_diameter=0.0079",
                                  "timestep.dt=7e-7", "output.vtk=false", "crusher.release_time=0.15",
                                  "scene.end_time=0.3", "experiment.breakage.start=\"" + start + "\""})
      args.insert(args.end(), {"--set", set});
    REQUIRE(test::cli(args) == 0);
    std::ifstream in(out / "results.json");
    const auto b = nlohmann::json::parse(in)["crusher"]["breakage"];
    INFO(start << ": " << b.dump());
    CHECK(b["start"] == start);
    CHECK(b["checks_from_s"].get<double>() == (start == "feed" ? 0.0 : 0.15));
    REQUIRE(b["events"].get<int>() >= 1);
    std::istringstream events(test::slurp(out / "breakage.csv"));
    std::string header, first;
    std::getline(events, header);
    std::getline(events, first);
    (start == "feed" ? first_feed : first_release) = std::stod(first.substr(0, first.find(',')));
    fs::remove_all(out);
  }
  CHECK(first_feed < 0.15);     // in the bin
  CHECK(first_release >= 0.15); // in the chamber
}

TEST_CASE("a crusher run with breakage restarted from its checkpoint ends as the run that went straight through, bit "
          "for bit",
          "[cli][crusher][restart]") {
  // The tiny run above breaks its first ball at 0.102 s and two more by 0.17 s: the
  // restart at 0.12 s carries one event, the fragment materials and the driver's
  // counters, and must then break the other two exactly as the straight run does.
  const fs::path root = test::scratchDir("crusher-restart");
  auto args = [&](const std::string& out, const std::string& end) {
    auto a = test::tinyCrusherRunArgs((root / out).string());
    for (const char* set : {"experiment.breakage.q_ref=2e5", "experiment.breakage.check_interval=2e-5",
                            "experiment.breakage.youngs_modulus=1e8", "experiment.breakage.min_diameter=0.0079",
                            "timestep.dt=7e-7", "output.vtk=false", "output.checkpoint=true"})
      a.insert(a.end(), {"--set", set});
    a.insert(a.end(), {"--set", "scene.end_time=" + end});
    return a;
  };
  REQUIRE(test::cli(args("straight", "0.25")) == 0);
  REQUIRE(test::cli(args("first", "0.12")) == 0);
  REQUIRE(test::cli({"restart", (root / "first" / "checkpoint.h5").string(), "--out", (root / "second").string(),
                     "--quiet", "--set", "scene.end_time=0.25"}) == 0);
  const auto results = [&](const std::string& out) {
    std::ifstream in(root / out / "results.json");
    return nlohmann::json::parse(in);
  };
  const nlohmann::json straight = results("straight"), first = results("first"), second = results("second");
  const int events = straight["crusher"]["breakages"].get<int>();
  CHECK(first["crusher"]["breakages"].get<int>() >= 1);      // the restart carries events...
  CHECK(first["crusher"]["breakages"].get<int>() < events);  // ...and makes new ones
  CHECK(second["status"] == "completed");
  CHECK(second["state_hash"] == straight["state_hash"]);
  // The product, the breakage log and the mass balance bit for bit. The mantle's
  // work is a sum the engine regroups when a World is rebuilt (the restart is one
  // rebuild more), so it agrees to round-off.
  nlohmann::json c2 = second["crusher"], c1 = straight["crusher"];
  const double work2 = c2["power"]["energy_J"].get<double>(), work1 = c1["power"]["energy_J"].get<double>();
  CHECK(work2 == Approx(work1).epsilon(1e-12));
  CHECK(c2["power"]["samples"] == c1["power"]["samples"]);
  for (nlohmann::json* c : {&c1, &c2}) {
    c->erase("power");
    c->erase("power_W");
  }
  CHECK(c2 == c1);
  CHECK(test::slurp(root / "second" / "breakage.csv") == test::slurp(root / "straight" / "breakage.csv"));
  CHECK(test::slurp(root / "second" / "product.csv") == test::slurp(root / "straight" / "product.csv"));

  // The breakage table on at the restart of a run saved without it: refused, named.
  auto plain = test::tinyCrusherRunArgs((root / "plain").string());
  plain.insert(plain.end(), {"--set", "output.checkpoint=true", "--set", "output.vtk=false", "--set",
                             "scene.end_time=0.05"});
  REQUIRE(test::cli(plain) == 0);
  std::string log;
  CHECK(test::cliLogged({"restart", (root / "plain" / "checkpoint.h5").string(), "--out", (root / "third").string(),
                         "--set", "experiment.breakage.q_ref=2e5"},
                        log) == 2);
  CHECK_THAT(log, Contains("/experiment") && Contains("without [experiment.breakage]"));
  CHECK(!fs::exists(root / "third" / "results.json"));
  fs::remove_all(root);
}
