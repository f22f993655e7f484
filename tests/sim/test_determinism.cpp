// Same results on 1 and 2 threads (bitwise), and restart = uninterrupted run.
#include <catch2/catch.hpp>
#include <filesystem>

#include "rocklab/geometry/packing.h"
#include "rocklab/sim/output/checkpoint.h"
#include "support.h"

using namespace rocklab;
using test::Vec3;

namespace {
/// A packed, frictional, damped heap: contacts with shear history everywhere.
sim::Model heapModel() {
  auto model = test::linearModel(2e7, 0.4, 0.1);
  model.gravity = Vec3(1.0, 0, -9.81);
  model.walls.push_back(test::floorPlane());
  return model;
}
std::vector<sim::SphereSpec> lattice(int nx, int ny, int nz) {
  std::vector<sim::SphereSpec> s;
  geometry::Rng rng(1);
  for (const Vec3& x : geometry::latticePoints(geometry::LatticeKind::SimpleCubic, 0.0199, Vec3(0.5, 0.5, 0.5),
                                               Vec3::Zero(), {nx, ny, nz}))
    s.push_back(test::sphere(x, 0.01 - 0.001 * rng.uniform(), {0.01 * rng.uniform(), 0, 0}));
  return s;
}
}  // namespace

TEST_CASE("bitwise identical on 1 and 2 threads", "[determinism]") {
  const auto s = lattice(30, 20, 10);  // 6000 balls: enough for a 2-thread team
  std::uint64_t hash[2];
  for (int t : {1, 2}) {
    sim::World w(heapModel(), s, t);
    for (int k = 0; k < 300; ++k) w.step();
    hash[t - 1] = w.stateHash();
  }
  CHECK(hash[0] == hash[1]);
}

TEST_CASE("restart from a checkpoint continues bit for bit", "[determinism]") {
  const auto s = lattice(8, 8, 6);
  sim::World full(heapModel(), s, 1);
  for (int k = 0; k < 5000; ++k) full.step();

  sim::World first(heapModel(), s, 1);
  for (int k = 0; k < 2634; ++k) first.step();
  const auto path = std::filesystem::temp_directory_path() / "rocklab-restart-test.h5";
  sim::output::writeCheckpoint(path, first.exportState(), "scene text");
  auto cp = sim::output::readCheckpoint(path);
  std::filesystem::remove(path);
  REQUIRE(!cp.state.pair_history.empty());  // the history really is carried
  sim::World second(heapModel(), std::move(cp.state), 1);
  while (second.stepCount() < 5000) second.step();
  CHECK(second.stateHash() == full.stateHash());
  CHECK(second.time() == full.time());
}
