// Long runs at the study's stiffness (label `validation`, not in CI):
//   ctest --test-dir build -L validation      (about 45 min on 2 cores)
// They check the set-up against what the lab states as input (an ~80 mm layer
// of 1680 pebbles), and that the demo's softened contacts do not move the
// figures beyond what is stated in the README.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"

namespace fs = std::filesystem;
using namespace rocklab::experiments;
using json = nlohmann::json;

namespace {
json runScene(const std::string& name, const std::vector<std::string>& overrides = {}) {
  const fs::path dir = fs::temp_directory_path() / ("rocklab-validation-" + name);
  fs::remove_all(dir);
  RunOptions o;
  o.out_dir = dir;
  o.progress = false;
  std::ostringstream log;
  const int code = rocklab::experiments::runScene(loadScene(resolveScene(name), overrides), o, log);
  INFO(log.str());
  REQUIRE(code == kExitOk);
  std::ifstream in(dir / "results.json");
  return json::parse(in);
}
}  // namespace

TEST_CASE("chute at the lab stiffness: an 80 mm layer that clears like the demo", "[validation]") {
  const json lab = runScene("chute-30-clumps");
  const json demo = runScene("demo");
  INFO(lab.dump(2));
  // The lab loaded 1680 pebbles into an ~80 mm layer (experiments.md §c).
  CHECK(lab["chute"]["bed_height_m"].get<double>() == Approx(0.08).margin(0.01));
  REQUIRE(lab["clearance_time_s"].is_number());
  CHECK(lab["jammed"] == false);
  int measured = 0;
  for (const auto& m : lab["markers"]) measured += m["truth_velocity_mps"].is_number();
  CHECK(measured >= 18);
  // Softening the contacts 100x (the demo) moves the clearance time by less than 5 %.
  CHECK(demo["clearance_time_s"].get<double>() == Approx(lab["clearance_time_s"].get<double>()).epsilon(0.05));
}

TEST_CASE("the demo's figures: markers tracked, tracking error and clearance time within its studies' scatter",
          "[validation]") {
  const json r = runScene("demo");
  INFO(r.dump(2));
  CHECK(r["status"] == "completed");
  CHECK(r["jammed"] == false);
  // Clearance: the chute-timestep study ran this scene (1e7 N/m, the default
  // step) with seeds 1, 2, 3: 1.2685 / 1.2225 / 1.2725 s, mean 1.2545 s, seed
  // scatter 0.028 s (docs/studies.md). The demo is seed 1: within 3 scatters of the mean.
  REQUIRE(r["clearance_time_s"].is_number());
  CHECK(r["clearance_time_s"].get<double>() == Approx(1.2545).margin(3 * 0.028));
  CHECK(r["chute"]["discharged_bodies"] == 1680);
  // Tracking against the DEM truth: the demo's tracking studies (docs/studies.md:
  // frame rate, resolution, noise) measured 12-19 of 20 markers compared (12 only
  // at sensor noise 15, 3x the demo's), RMS 0.48-0.64 % and max 1.05-1.27 %; the
  // README's run of the demo 0.93 % RMS with 16 of 20. Bounds: at least 14 of 20
  // markers, RMS below 1.5 % and no marker off by more than 3 % (issue 6).
  REQUIRE(r.contains("tracking"));
  const json& t = r["tracking"];
  REQUIRE(r["markers"].size() == 20);
  CHECK(t["markers_compared"].get<int>() >= 14);
  CHECK(t["markers_tracked"].get<int>() >= t["markers_compared"].get<int>());
  REQUIRE(t["rms_error_pct"].is_number());
  CHECK(t["rms_error_pct"].get<double>() < 1.5);
  CHECK(t["max_error_pct"].get<double>() < 3.0);
  // ...through the camera it calibrated itself (issue 6: focal length within 0.5 %).
  CHECK(std::abs(t["calibration"]["fx_px"]["error"].get<double>()) < 0.005 * t["calibration"]["fx_px"]["true"].get<double>());
}
