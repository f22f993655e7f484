// Same results on 1 and 2 threads (bitwise), and restart = uninterrupted run.
#include <catch2/catch.hpp>
#include <omp.h>

#include <unistd.h>

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
  // Two threads really run: the engine's team for this world has two members
  // (6000 balls / 2500 per thread), and OpenMP grants a team of two here (the
  // engine's parallel regions ask for num_threads(team)); with one thread
  // (OMP_THREAD_LIMIT=1, a world too small) the equality below would prove nothing.
  int granted = 0;
#pragma omp parallel num_threads(2)
#pragma omp single
  granted = omp_get_num_threads();
  REQUIRE(granted == 2);
  for (int t : {1, 2}) {
    sim::World w(heapModel(), s, t);
    REQUIRE(w.threads() == t);
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

TEST_CASE("relaxation offsets survive a checkpoint file: read back, the restart continues bit for bit",
          "[determinism]") {
  // Three balls created overlapping by 10-20 % of a radius, eased apart over 4000
  // steps (Model::relaxation); the checkpoint is written half-way, when every
  // offset is still non-zero and different from the one it started with.
  auto model = test::linearModel(1e7, 0.3, 0.1);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls.push_back(test::floorPlane());
  model.relaxation.steps = 4000;
  const double r = 0.01;
  const std::vector<sim::SphereSpec> s{test::sphere({0, 0, 0.9 * r}, r), test::sphere({0, 0, 2.7 * r}, r),
                                       test::sphere({0.4 * r, 0, 4.5 * r}, r)};
  sim::World full(model, s, 1);
  for (int k = 0; k < 6000; ++k) full.step();

  sim::World first(model, s, 1);
  for (int k = 0; k < 2000; ++k) first.step();
  const sim::WorldState mid = first.exportState();
  const auto path = std::filesystem::temp_directory_path() /
                    ("rocklab-relax-checkpoint-" + std::to_string(::getpid()) + ".h5");
  sim::output::writeCheckpoint(path, mid, "scene text");
  auto cp = sim::output::readCheckpoint(path);
  std::filesystem::remove(path);
  int offsets = 0;
  REQUIRE(cp.state.pair_history.size() == mid.pair_history.size());
  for (std::size_t k = 0; k < mid.pair_history.size(); ++k) {
    CHECK(cp.state.pair_history[k].relax_offset == mid.pair_history[k].relax_offset);
    offsets += mid.pair_history[k].relax_offset > 0;
  }
  REQUIRE(cp.state.wall_history.size() == mid.wall_history.size());
  for (std::size_t k = 0; k < mid.wall_history.size(); ++k) {
    CHECK(cp.state.wall_history[k].relax_offset == mid.wall_history[k].relax_offset);
    offsets += mid.wall_history[k].relax_offset > 0;
  }
  CHECK(offsets == 3);  // two ball pairs and the floor contact are still relaxing
  sim::World second(model, std::move(cp.state), 1);
  while (second.stepCount() < 6000) second.step();
  CHECK(second.stateHash() == full.stateHash());
}
