// A saved state is input: a World restarting from one checks every value
// (state_check.h) and names the dataset and row; a checkpoint's checksums catch
// random damage, and files without them are read but said to be unchecked.
#include <H5Cpp.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>

#include "rocklab/sim/output/checkpoint.h"
#include "rocklab/sim/output/run_file.h"
#include "rocklab/sim/world.h"
#include "support/sim_builders.h"

using namespace rocklab;
using geometry::Quat;
using geometry::Vec3;
namespace fs = std::filesystem;

namespace {

sim::Model twoMaterials() {
  sim::Model m;
  m.materials = {sim::Material{"ball", 2650.0, 1e6, 1e6, 0.5, 0.0, 0.2},
                 sim::Material{"wall", 7800.0, 1e6, 1e6, 0.5, 0.0, 0.2}};
  m.walls = {test::floorPlane()};
  m.bonds.normal_stiffness = 1e9;  // Pa/m
  m.bonds.shear_stiffness = 4e8;
  return m;
}

/// Two spheres on the floor side by side (pair and wall history), a
/// two-ball clump above them and a parallel bond between the spheres, after a
/// few steps: every kind of array a checkpoint holds.
sim::WorldState savedState(const sim::Model& model) {
  const double r = 0.01;
  sim::ClumpSpec clump;
  clump.position = {0, 0.05, 0.05};
  clump.mass = 2e-2;
  clump.principal_inertia = {1e-6, 2e-6, 2e-6};
  clump.members = {{Vec3(-0.5 * r, 0, 0), r}, {Vec3(0.5 * r, 0, 0), r}};
  sim::BondSpec bond;
  bond.a = 0;
  bond.b = 1;
  // The second sphere slides sideways: shear history at the pair and the floor.
  sim::World w(model, {test::sphere({0, 0, 0.99 * r}, r), test::sphere({1.98 * r, 0, 0.99 * r}, r, {0, 0.01, 0})},
               {clump}, {bond}, 1);
  for (int k = 0; k < 5; ++k) w.step();  // still touching: the overlaps push them apart slowly
  return w.exportState();
}

/// The message a World restarting from `state` refuses it with ("" if it does not).
std::string refusal(const sim::Model& model, sim::WorldState state) {
  try {
    sim::World w(model, std::move(state), 1);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("rocklab-saved-state-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

}  // namespace

TEST_CASE("restart: every bad value of a saved state is refused with its dataset, row and what is allowed",
          "[checkpoint]") {
  const sim::Model model = twoMaterials();
  const sim::WorldState good = savedState(model);
  REQUIRE(good.pair_history.size() > 0);
  REQUIRE(good.wall_history.size() > 0);
  REQUIRE(refusal(model, good).empty());  // the state as saved restarts

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* what;
    std::function<void(sim::WorldState&)> damage;
    const char* expected;  // in the message
  };
  const std::vector<Case> cases = {
      {"negative material", [](auto& s) { s.particles.material[0] = -5; }, "particles/material row 0: -5 (allowed: 0 to 1"},
      {"material past the table", [](auto& s) { s.particles.material[1] = 99; }, "particles/material row 1: 99"},
      {"zero radius", [](auto& s) { s.particles.radius[1] = 0.0; }, "particles/radius row 1: 0 (allowed: > 0 m"},
      {"negative radius", [](auto& s) { s.particles.radius[0] = -0.01; }, "particles/radius row 0: -0.01"},
      {"NaN radius", [nan](auto& s) { s.particles.radius[2] = nan; }, "particles/radius row 2: nan (allowed: finite)"},
      {"infinite position", [inf](auto& s) { s.particles.position[1].y() = inf; }, "particles/position row 1"},
      {"NaN velocity", [nan](auto& s) { s.particles.velocity[0].x() = nan; }, "particles/velocity row 0"},
      {"mass and inverse disagree", [](auto& s) { s.particles.inv_mass[0] *= 2; }, "particles/inv_mass row 0"},
      {"zero inverse inertia", [](auto& s) { s.particles.inv_inertia[1] = 0; }, "particles/inv_inertia row 1: 0"},
      {"an id twice", [](auto& s) { s.particles.id[3] = s.particles.id[0]; }, "particles/id row"},
      {"clump index of 2e9", [](auto& s) { s.particles.clump[2] = 2000000000; }, "particles/clump row 2: 2000000000"},
      {"free ball listed as a member", [](auto& s) { s.particles.clump[3] = -1; }, "clumps/member_ball row 1: ball 3"},
      {"member past the balls", [](auto& s) { s.particles.clumps.member_ball[0] = 40; }, "clumps/member_ball row 0: 40"},
      {"zero quaternion", [](auto& s) { s.particles.clumps.orientation[0] = Quat(0, 0, 0, 0); },
       "clumps/orientation row 0: (0, 0, 0, 0) (allowed: a unit quaternion"},
      {"zero clump mass", [](auto& s) { s.particles.clumps.mass[0] = 0; }, "clumps/mass row 0: 0"},
      {"negative moment", [](auto& s) { s.particles.clumps.inertia[0].y() = -1; }, "clumps/inertia row 0"},
      {"zero dt", [](auto& s) { s.dt = 0; }, "attribute dt: 0 s (allowed: > 0 s, finite)"},
      {"negative dt", [](auto& s) { s.dt = -1e-6; }, "attribute dt: -1e-06 s"},
      {"NaN time", [nan](auto& s) { s.time = nan; }, "attribute time: nan s"},
      {"time and step disagree", [](auto& s) { s.time += 1.0; }, "(allowed: time = step x dt)"},
      {"step of 2^60", [](auto& s) { s.step = std::uint64_t{1} << 60; }, "attribute step: 1152921504606846976"},
      {"pair out of order", [](auto& s) { std::swap(s.pair_history[0].i, s.pair_history[0].j); }, "pairs/j row 0"},
      {"pair with a missing ball", [](auto& s) { s.pair_history[0].j = 77; }, "pairs/j row 0: 77"},
      {"NaN shear", [nan](auto& s) { s.pair_history[0].shear.z() = nan; }, "pairs/shear row 0"},
      {"missing wall", [](auto& s) { s.wall_history[0].wall = 7; }, "walls/wall row 0: 7 (allowed: 0 to 0, the scene has 1 walls)"},
      {"wall contact of a missing ball", [](auto& s) { s.wall_history[0].particle = 9; }, "walls/particle row 0: 9"},
      {"second contact slot on a plane", [](auto& s) { s.wall_history[0].slot = 1; }, "walls/slot row 0: 1 (allowed: 0 for the wall '"},
      {"NaN contact normal", [nan](auto& s) { s.wall_history[0].normal.x() = nan; }, "walls/normal row 0"},
      {"bond end past the balls", [](auto& s) { s.bonds.b[0] = 1000; }, "bonds/b row 0: 1000"},
      {"bond kind 7", [](auto& s) { s.bonds.kind[0] = 7; }, "bonds/kind row 0: 7 (allowed: 0 parallel, 1 contact)"},
      {"bond intact 2", [](auto& s) { s.bonds.intact[0] = 2; }, "bonds/intact row 0: 2"},
      {"NaN bond force", [nan](auto& s) { s.bonds.normal_force[0] = nan; }, "bonds/normal_force row 0"},
      {"size mismatch", [](auto& s) { s.particles.mass.pop_back(); }, "inconsistent array sizes: particles/mass"},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    sim::WorldState damaged = good;
    c.damage(damaged);
    CHECK_THAT(refusal(model, damaged), Catch::Contains(c.expected));
  }
}

TEST_CASE("checkpoint: a changed byte fails its checksum - a file without checksums is read unchecked",
          "[checkpoint]") {
  H5::Exception::dontPrint();
  const sim::Model model = twoMaterials();
  const sim::WorldState state = savedState(model);
  TempDir dir;
  const fs::path path = dir.path / "checkpoint.h5";
  sim::output::writeCheckpoint(path, state, "scene");
  REQUIRE(sim::output::readCheckpoint(path).unchecked == 0);

  SECTION("random bytes in an array") {
    {
      H5::H5File file(path.string(), H5F_ACC_RDWR);
      std::vector<double> radius = state.particles.radius;
      radius[1] = 0.0125;  // a plausible value: only the checksum tells
      file.openDataSet("/particles/radius").write(radius.data(), H5::PredType::NATIVE_DOUBLE);
    }
    try {
      sim::output::readCheckpoint(path);
      FAIL("a damaged checkpoint was read");
    } catch (const sim::output::CheckpointError& e) {
      CHECK_THAT(e.what(), Catch::Contains(path.string()) && Catch::Contains("dataset /particles/radius") &&
                               Catch::Contains("checksum mismatch"));
    }
  }
  SECTION("a changed run attribute") {
    {
      H5::H5File file(path.string(), H5F_ACC_RDWR);
      const double dt = state.dt * 2;
      file.openAttribute("dt").write(H5::PredType::NATIVE_DOUBLE, &dt);
    }
    CHECK_THROWS_WITH(sim::output::readCheckpoint(path),
                      Catch::Contains("attributes time, step, dt, half_kick_pending: checksum mismatch"));
  }
  SECTION("an old file without checksums") {
    {
      H5::H5File file(path.string(), H5F_ACC_RDWR);
      file.removeAttr("run_crc32");
      file.openDataSet("/particles/radius").removeAttr("crc32");
    }
    const sim::output::Checkpoint cp = sim::output::readCheckpoint(path);
    CHECK(cp.unchecked == 2);
    CHECK(cp.state.particles.radius == state.particles.radius);
  }
}

namespace {

/// Every dataset in the file, with whether it has each of `attributes`.
std::vector<std::string> datasetsLacking(const fs::path& path, const char* attribute) {
  struct Visit {
    const char* attribute;
    std::vector<std::string> lacking;
    int datasets = 0;
  } visit{attribute, {}, 0};
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  H5Ovisit(
      file, H5_INDEX_NAME, H5_ITER_INC,
      [](hid_t root, const char* name, const H5O_info_t* info, void* data) -> herr_t {
        auto& v = *static_cast<Visit*>(data);
        if (info->type != H5O_TYPE_DATASET) return 0;
        ++v.datasets;
        if (H5Aexists_by_name(root, name, v.attribute, H5P_DEFAULT) <= 0) v.lacking.push_back(name);
        return 0;
      },
      &visit);
  H5Fclose(file);
  REQUIRE(visit.datasets > 10);
  return visit.lacking;
}

}  // namespace

TEST_CASE("every dataset of checkpoint.h5 and run.h5 carries a unit and a checksum", "[checkpoint][output]") {
  const sim::Model model = twoMaterials();
  TempDir dir;
  sim::output::writeCheckpoint(dir.path / "checkpoint.h5", savedState(model), "scene");
  {
    sim::World w(model, savedState(model), 1);
    sim::output::RunFile run(dir.path / "run.h5", "scene");
    w.step([&](const sim::Snapshot& s) {
      run.writeFrame(s);
      run.appendEnergy(s);
    });
    run.close(false);
  }
  for (const char* file : {"checkpoint.h5", "run.h5"}) {
    INFO(file);
    CHECK(datasetsLacking(dir.path / file, "unit").empty());
    // The energy table grows row by row: it has no checksum (readers do not read it).
    CHECK(datasetsLacking(dir.path / file, "crc32") ==
          (std::string(file) == "run.h5" ? std::vector<std::string>{"energy"} : std::vector<std::string>{}));
  }
}
