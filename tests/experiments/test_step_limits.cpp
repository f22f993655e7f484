// The step count and its clock: an end no step count reaches is refused naming
// the key and value, results.json never reports a negative stepping time, and a
// step forced so large that a ball passes a wall unseen is warned about loudly.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_support.h"

namespace fs = std::filesystem;
using rocklab::experiments::test::cli;
using rocklab::experiments::test::cliLogged;

namespace {

fs::path tempDir(const std::string& name) { return rocklab::experiments::test::scratchDir("steps-" + name); }

nlohmann::json results(const fs::path& dir) {
  std::ifstream in(dir / "results.json");
  return nlohmann::json::parse(in);
}


// A 10 mm ball 45 mm above a square plate, falling at 30 m/s without gravity;
// the step is forced to 1 ms, so it moves 3 cm, three radii, in one step: from
// 15 mm above the plate to 15 mm below it, never touching it.
const char* kFastBall = R"(
[scene]
name = "fast-ball"
end_time = 0.01

[materials.ball]
kn = 1e6

[gravity]
vector = [0, 0, 0]

[timestep]
dt = 1e-3
allow_unsafe = true

[[walls]]
type = "polygon"
name = "plate"
material = "ball"
vertices = [[-0.1, -0.1, 0], [0.1, -0.1, 0], [0.1, 0.1, 0], [-0.1, 0.1, 0]]

[[particles]]
type = "list"
material = "ball"
positions = [[0, 0, 0.045]]
radii = [0.01]
velocities = [[0, 0, -30]]

[output]
checkpoint = false
)";

const std::string kHopper = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/hopper.toml";

}  // namespace

TEST_CASE("an end the step count cannot reach is refused with the key and its value", "[cli]") {
  const fs::path out = tempDir("overflow");
  const std::vector<std::string> run = {"run", kHopper, "--quiet", "--out", out.string(), "--set",
                                        "particles.0.count=20"};
  std::string log;
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = run;
    args.insert(args.end(), extra.begin(), extra.end());
    return cliLogged(args, log);
  };
  CHECK(with({"--set", "scene.end_time=1e300"}) == 2);
  CHECK_THAT(log, Catch::Contains("scene.end_time = 1e+300 s is") && Catch::Contains("the automatic step") &&
                      Catch::Contains("more than 2^53"));
  CHECK(with({"--set", "timestep.dt=1e-300"}) == 2);
  CHECK_THAT(log, Catch::Contains("dt = 1e-300 s (timestep.dt)") && Catch::Contains("or raise timestep.dt"));
  CHECK_FALSE(fs::exists(out));
}

TEST_CASE("a run of one step reports a stepping time >= 0", "[cli]") {
  // The final checkpoint and run.h5 close are output time after the loop: they
  // were subtracted from a loop that did not contain them.
  const fs::path out = tempDir("one-step");
  for (int k = 0; k < 3; ++k) {
    REQUIRE(cli({"run", kHopper, "--quiet", "--overwrite", "--out", out.string(), "--set", "particles.0.count=200",
                 "--set", "scene.end_time=0", "--set", "scene.steps=1"}) == 0);
    const auto r = results(out);
    CHECK(r["wall_time_s"]["stepping"].get<double>() >= 0);
    CHECK(r["particle_steps_per_s"].get<double>() >= 0);
  }
  fs::remove_all(out);
}

TEST_CASE("allow_unsafe: a ball that moves past its radius in one step is warned about, logged and in results.json",
          "[cli]") {
  const fs::path out = tempDir("fast");
  fs::create_directories(out);
  std::ofstream(out / "fast.toml") << kFastBall;
  std::string log;
  REQUIRE(cliLogged({"run", (out / "fast.toml").string(), "--quiet", "--out", (out / "run").string()}, log) == 0);
  CHECK_THAT(log, Catch::Contains("warning: at t = 0 s (step 0) particle 0 moved 0.03 m in one step, 3 x its radius") &&
                      Catch::Contains("timestep.allow_unsafe"));
  const auto r = results(out / "run");
  REQUIRE(r["warnings"].size() == 1);
  CHECK_THAT(r["warnings"][0].get<std::string>(), Catch::Contains("can pass through a wall"));

  // A safe step: no warning.
  REQUIRE(cliLogged({"run", (out / "fast.toml").string(), "--quiet", "--out", (out / "safe").string(), "--set",
                     "timestep.dt=0", "--set", "timestep.allow_unsafe=false"},
                    log) == 0);
  const auto safe = results(out / "safe");
  CHECK(safe["warnings"].empty());
  CHECK(safe["last_observed"]["energy_J"]["kinetic_translational"].get<double>() > 0);
  CHECK(log.find("warning:") == std::string::npos);
  fs::remove_all(out);
}
