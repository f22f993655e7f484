// The watchdog's messages: what stopped the run and what to change.
#include <catch2/catch.hpp>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "rocklab/sim/force_contribution.h"

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

namespace {
/// Adds a NaN force to one ball from a given step on: a blow-up that no other
/// check sees first (no contact, no observed step, so no energy check).
class NanForce : public sim::ForceContribution {
 public:
  NanForce(std::uint32_t ball, std::uint64_t from_step) : ball_(ball), from_(from_step) {}
  std::string name() const override { return "nan force"; }
  void addForces(const sim::ForceInput&, std::span<Vec3> force, std::span<Vec3>) override {
    if (calls_++ >= from_) force[ball_].x() += std::numeric_limits<double>::quiet_NaN();
  }
  double potentialEnergy(const sim::ForceInput&) const override { return 0.0; }

 private:
  std::uint32_t ball_;
  std::uint64_t from_, calls_ = 0;
};
}  // namespace

TEST_CASE("watchdog: a non-finite state stops the run in the step it appears, naming the particle", "[watchdog]") {
  auto model = test::linearModel(2e7);
  sim::World w(model, {test::sphere({0, 0, 0}, 0.01), test::sphere({0.1, 0, 0}, 0.01), test::sphere({0.2, 0, 0}, 0.01)},
               1);
  w.addForceContribution(std::make_shared<NanForce>(1, 10));
  std::string message;
  try {
    for (int k = 0; k < 100; ++k) w.step();
  } catch (const sim::WatchdogError& e) {
    message = e.what();
  }
  CHECK_THAT(message, Catch::Contains("particle 1 has a non-finite position or velocity") &&
                          Catch::Contains("(step 11)") && Catch::Contains("the run blew up"));
  // The NaN enters in the 11th step (calls 0..10): it is counted and no further step runs.
  CHECK(w.stepCount() == 11);
}
