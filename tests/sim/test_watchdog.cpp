// The watchdog's messages: what stopped the run and what to change.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "support.h"

using namespace rocklab;
using test::Vec3;

TEST_CASE("watchdog: a forced oversize step is stopped with a message that says what to change", "[walls][watchdog]") {
  auto model = test::linearModel(2e7, 0.3, 0.0);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls.push_back(test::floorPlane());
  std::vector<sim::SphereSpec> s;
  for (int k = 0; k < 20; ++k) s.push_back(test::sphere({0.021 * (k % 5), 0.021 * (k / 5), 0.0101}, 0.01));
  sim::World probe(model, s, 1);
  model.timestep.dt = 5 * probe.timestepAudit().critical;
  model.timestep.allow_unsafe = true;
  sim::World w(model, s, 1);
  std::string message;
  std::uint64_t steps = 0;
  try {
    for (; steps < 100000; ++steps) w.step();
  } catch (const sim::WatchdogError& e) {
    message = e.what();
  }
  CHECK(steps < 2000);  // caught quickly
  CHECK_THAT(message, Catch::Contains("watchdog") && Catch::Contains("particle") &&
                          Catch::Contains("x the critical step") && Catch::Contains("lower timestep.dt"));
}

TEST_CASE("watchdog: spheres created deeply overlapping are reported by id", "[walls][watchdog]") {
  auto model = test::linearModel(2e7);
  std::vector<sim::SphereSpec> s{test::sphere({0, 0, 0}, 0.01), test::sphere({0.009, 0, 0}, 0.01)};
  sim::World w(model, s, 1);
  CHECK_THROWS_WITH(w.step(), Catch::Contains("overlap of particle 0 with particle 1") &&
                                  Catch::Contains("watchdog.max_overlap_fraction = 0.5"));
}
