// The experiment drivers on small, soft versions of the real scenes: drop
// restitution against Eq 4-4, the drop calibration, a heap with a non-zero
// angle, a chute that discharges and one that jams. The full scenes are the
// `validation` runs (README).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "cli_support.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/experiments/sweep.h"
#include "rocklab/sim/output/run_file.h"
#include "rocklab/sim/timestep.h"

namespace fs = std::filesystem;
using namespace rocklab::experiments;
using json = nlohmann::json;

namespace {

const std::string kAssets = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/";

/// Softer contacts for CI (the rigid limit is the same; kn = 1e9 costs 30x the steps).
std::vector<std::string> soft(const std::vector<std::string>& materials, double k) {
  std::vector<std::string> o;
  for (const auto& m : materials) {
    o.push_back("materials." + m + ".kn=" + std::to_string(k));
    o.push_back("materials." + m + ".ks=" + std::to_string(k));
  }
  return o;
}

json runFor(const std::string& scene_path, std::vector<std::string> overrides, const std::string& dir_name,
            int expected_code = kExitOk) {
  const fs::path dir = fs::temp_directory_path() / ("rocklab-exp-" + dir_name);
  fs::remove_all(dir);
  const Scene scene = loadScene(scene_path, overrides);
  RunOptions options;
  options.out_dir = dir;
  options.threads = 2;
  options.progress = false;
  std::ostringstream log;
  const int code = runScene(scene, options, log);
  INFO(log.str());
  REQUIRE(code == expected_code);
  std::ifstream in(dir / "results.json");
  return json::parse(in);
}

}  // namespace

TEST_CASE("drop: measured restitution follows Eq 4-4 and converges with the step", "[experiment]") {
  const double analytic = rocklab::sim::restitutionFromDamping(0.11);
  const json coarse = runFor(kAssets + "drop.toml", {}, "drop-coarse");
  const json fine = runFor(kAssets + "drop.toml", {"timestep.safety_factor=0.1"}, "drop-fine");
  const double e_coarse = coarse["restitution"].get<double>(), e_fine = fine["restitution"].get<double>();
  INFO("e at dt = 0.5 dt_crit: " << e_coarse << ", at 0.1 dt_crit: " << e_fine << ", Eq 4-4: " << analytic);
  CHECK(std::abs(e_coarse - analytic) < 0.02);
  CHECK(std::abs(e_fine - analytic) < 0.005);
  CHECK(std::abs(e_fine - analytic) < std::abs(e_coarse - analytic));
  // Contact with the plate: pi / omega_d for the ball mass and the series stiffness 5e8 N/m.
  const double m = 2730.0 * 4.0 / 3.0 * M_PI * 1e-6;
  const double tc = rocklab::sim::linearContactTime(m, 5e8, 0.11);
  CHECK(fine["drop"]["contact_time_s"].get<double>() == Approx(tc).epsilon(0.05));
}

TEST_CASE("calibrate: finds the damping ratio for a target restitution", "[experiment]") {
  CalibrateOptions c;
  c.sweep.scene = kAssets + "drop.toml";
  c.sweep.vary = {parseVary("contact.damping_normal=0.05,0.1,0.15")};
  c.sweep.overrides = {"contact.damping_shear=0.2"};  // the check it suggests must carry it
  c.sweep.out_dir = fs::temp_directory_path() / "rocklab-exp-calibrate";
  c.sweep.progress = false;
  c.target_metric = "restitution";
  c.target = 0.72;
  fs::remove_all(c.sweep.out_dir);
  std::ostringstream log;
  REQUIRE(runCalibrate(c, log) == kExitOk);
  INFO(log.str());
  std::ifstream in(c.sweep.out_dir / "calibration.json");
  const json r = json::parse(in);
  // Eq 4-4 inverted gives 0.1036 for e = 0.72; the dt = 0.5 dt_crit drop loses a little more.
  CHECK(r["estimate"].get<double>() == Approx(rocklab::sim::dampingFromRestitution(0.72)).margin(0.008));
  CHECK(fs::exists(c.sweep.out_dir / "calibration.csv"));
  CHECK(log.str().find("contact.damping_normal = 0.0") != std::string::npos);
  // The suggested check runs the scene as calibrated: its overrides, then the estimate.
  CHECK(log.str().find(" --set contact.damping_shear=0.2 --set contact.damping_normal=0.") != std::string::npos);
}

TEST_CASE("heap: a small heap of clumps stands at a non-zero angle", "[experiment]") {
  auto o = soft({"pebble", "table", "perspex"}, 1e6);
  o.push_back("particles.0.count=250");
  o.push_back("particles.0.region_max=[0.1, 0.1, 0.3]");
  o.push_back("experiment.settle_min_time=1.0");
  const json r = runFor(kAssets + "heap.toml", o, "heap");
  INFO(r.dump(2));
  REQUIRE(r["angle_of_repose_deg"].is_number());
  const double angle = r["angle_of_repose_deg"].get<double>();
  // This heap (250 softened clumps) over seeds 1, 3, 4, 5: 16.1, 19.5, 16.0, 14.9 deg
  // (mean 16.6, sd 2.0; seed 2 leaves one flank too low to be called a heap, and says
  // so): the band is the mean +- 3 sd of that scatter (`rocklab sweep heap --vary
  // scene.seed=1,2,3,4,5` with this test's --set values).
  CHECK(angle > 10.6);
  CHECK(angle < 22.6);
  CHECK(r["heap"]["flank_angles_deg"].size() == 4);
  // The side photograph (rendered, measured like a lab photo) agrees with the
  // angle from the positions within a few degrees.
  REQUIRE(r["heap"]["photograph"]["angle_deg"].is_number());
  CHECK(std::abs(r["heap"]["photograph"]["difference_to_geometric_deg"].get<double>()) < 4.0);
  // ...read through the camera calibrated on a board in the plane of the heap axis.
  const json& fx = r["heap"]["photograph"]["calibration"]["fx_px"];
  CHECK(std::abs(fx["error"].get<double>()) < 0.005 * fx["true"].get<double>());
}

TEST_CASE("product photo: spheres on a tray sized from the top image agree with their true sizes", "[experiment]") {
  const json r = runFor(kAssets + "product-photo.toml",
                        {"particles.0.count=60", "experiment.settle_max_time=1.0", "cameras.top.movie=false"},
                        "product-photo");
  INFO(r.dump(2));
  const json& s = r["product_photo"];
  REQUIRE(s["particles"].is_object());
  const int in_view = s["particles"]["true_in_view"].get<int>();
  CHECK(in_view == 60);
  // A monolayer under a dome light: every ball is one particle of the image, sized to
  // about a pixel (0.42 mm) or 1.5 % RMS (measured 0.9 % with 150 balls).
  CHECK(s["particles"]["matched"].get<int>() >= 57);
  CHECK(s["particles"]["missed"].get<int>() == 0);
  CHECK(s["matched_diameter_error"]["rms_pct"].get<double>() < 2.5);
  CHECK(std::abs(s["matched_diameter_error"]["mean_pct"].get<double>()) < 1.5);
  const double p50_truth = s["p50_mm"]["truth"].get<double>(), p50_image = s["p50_mm"]["image"].get<double>();
  CHECK(std::abs(p50_image / p50_truth - 1.0) < 0.03);
  CHECK(s["max_passing_error_points"].get<double>() < 6.0);
  REQUIRE(s["psd"].size() == 9);
  const fs::path dir = fs::temp_directory_path() / "rocklab-exp-product-photo";
  CHECK(fs::exists(dir / "product_sizing.png"));
  CHECK(fs::exists(dir / "product_psd.png"));
  CHECK(fs::exists(dir / "product_particles.csv"));
}

TEST_CASE("chute: a short clump chute discharges and reports its markers", "[experiment]") {
  auto o = soft({"pebble", "steel", "perspex"}, 1e6);
  o.push_back("particles.0.count=300");
  o.push_back("particles.0.region_max=[0.6, 0.3, 0.15]");
  o.push_back("experiment.marker_heights=[0.01, 0.03]");
  o.push_back("experiment.tilt_steps=500");
  // 200 fps: at 50 fps a marker moves about its own radius per frame and the
  // linking gate (radius + 1 m/s per frame = 20 mm) reaches its neighbours (a
  // track jumped to another marker: 0.78 vs 0.36 m/s).
  o.push_back("cameras.side.frame_rate=200");
  const fs::path dir = fs::temp_directory_path() / "rocklab-exp-chute";
  const json r = runFor(kAssets + "chute-30-clumps.toml", o, "chute");
  INFO(r.dump(2));
  CHECK(r["jammed"] == false);
  REQUIRE(r["clearance_time_s"].is_number());
  CHECK(r["clearance_time_s"].get<double>() > 0.1);
  CHECK(r["chute"]["discharged_bodies"] == 300);
  REQUIRE(r["markers"].size() == 10);  // 5 columns x 2 heights
  int measured = 0;
  for (const auto& m : r["markers"]) {
    if (!m["truth_velocity_mps"].is_number()) continue;
    ++measured;
    // A marker cannot average more than free sliding down a frictionless 30 deg
    // slope over 100 mm (sqrt(2 g sin 30 x 0.1) / 2 = 0.5 m/s), nor stand still.
    CHECK(m["truth_velocity_mps"].get<double>() > 0.02);
    CHECK(m["truth_velocity_mps"].get<double>() < 0.6);
  }
  CHECK(measured >= 8);
  REQUIRE(r["profile"].size() == 5);
  CHECK(r["profile"][0]["distance_m"].get<double>() == Approx(0.1));
  for (const char* f : {"velocity_profile.png", "discharge.png", "markers.csv", "discharge.csv", "side_still_000000.png"})
    CHECK(fs::exists(dir / f));
  // The side camera filmed it: a movie, stills, and the GL it used.
  REQUIRE(r["cameras"].size() == 1);
  CHECK(r["cameras"][0]["frames"].get<int>() > 50);
  CHECK(fs::exists(dir / r["cameras"][0]["movie"].get<std::string>()));
  CHECK(r["cameras"][0]["gl_renderer"].get<std::string>().size() > 0);
  // The tracker (images only) against the truth: every marker followed over the
  // 100 mm window, each within 3 %, issue 25's bound for this chute. Measured with
  // the model-based position (track_position = "shape"): 10 of 10, max 1.27 %, RMS
  // 0.66 %; after the clump integrator's round-off changed (session 20, the same
  // physics, another realisation of the flow) 10 of 10, max 2.08 %, RMS 0.87 %:
  // the realisations' scatter is why the bound is not the first run's 2 %. The
  // centroid measured max 2.50 %, RMS 0.87 %. Before the prediction-seeded split,
  // the ambiguity ends and stitching, 6 of 7 were within 2.5 % and one +10.7 %:
  // hidden for 65 ms, its track resumed on a blob ahead.
  REQUIRE(r.contains("tracking"));
  const int compared = r["tracking"]["markers_compared"].get<int>();
  CHECK(compared >= 9);
  for (const auto& m : r["markers"])
    if (m["tracked_velocity_mps"].is_number() && m["truth_velocity_mps"].is_number()) {
      INFO("marker column " << m["column"] << " row " << m["row"]);
      CHECK(std::abs(m["tracked_velocity_mps"].get<double>() / m["truth_velocity_mps"].get<double>() - 1.0) < 0.03);
    }
  // The tracking-error report, frame by frame against the truth: no identity swap,
  // markers found in nearly every frame they are in view, a sub-pixel histogram.
  CHECK(r["tracking"]["position"] == "shape");
  CHECK(r["tracking"]["shape_fit"]["fitted"].get<int>() > 0);
  const json& report = r["tracking"]["error_report"];
  CHECK(report["identity_swaps"] == 0);
  CHECK(report["fraction_found"].get<double>() > 0.95);
  CHECK(report["pixel_error"]["u"]["rms_px"].get<double>() < 2.0);
  CHECK(report["world_error"]["x"]["rms_m"].get<double>() < 0.003);
  CHECK(report["subpixel_histogram"]["u"].size() == 10);
  CHECK(r["markers"][0]["fraction_found"].is_number());
  CHECK(fs::exists(dir / "tracking_error.png"));
  CHECK(r["markers"][0]["pixel_rms_px"].get<double>() < 3.0);
  {  // every pair of the report, truth beside tracked, a row each
    std::ifstream pairs(dir / "tracking_pairs.csv");
    std::string line;
    REQUIRE(std::getline(pairs, line));
    CHECK(line.rfind("frame,marker,track_id,truth_u_px", 0) == 0);
    int rows = 0;
    while (std::getline(pairs, line)) ++rows;
    CHECK(rows == report["pairs"].get<int>());
  }
  // ...with the camera it recovered from checkerboard photos, not the renderer's.
  const json& cal = r["tracking"]["calibration"];
  REQUIRE(cal.is_object());
  CHECK(cal["photos"] == 11);
  CHECK(std::abs(cal["fx_px"]["error"].get<double>()) < 0.005 * cal["fx_px"]["true"].get<double>());
  CHECK(std::abs(cal["fy_px"]["error"].get<double>()) < 0.005 * cal["fy_px"]["true"].get<double>());
  CHECK(cal["camera_position_error_m"].get<double>() < 0.005);
  CHECK(cal["view_direction_error_deg"].get<double>() < 0.5);
  CHECK(fs::exists(dir / "tracks.csv"));
  CHECK(fs::exists(dir / "profile.png"));
}

TEST_CASE("chute: a camera that cannot be calibrated leaves the run going and says why", "[experiment]") {
  auto o = soft({"pebble", "steel", "perspex"}, 1e6);
  o.push_back("particles.0.count=150");
  o.push_back("particles.0.region_max=[0.6, 0.3, 0.1]");
  o.push_back("experiment.marker_heights=[0.01]");
  o.push_back("experiment.tilt_steps=200");
  o.push_back("cameras.side.frame_rate=20");
  o.push_back("cameras.side.movie=false");
  o.push_back("cameras.side.target=[0.27, -1.5, 0.05]");  // looks away from the Perspex wall
  const json r = runFor(kAssets + "chute-30-clumps.toml", o, "uncalibrated");
  INFO(r.dump(2));
  CHECK(r["status"] == "completed");
  REQUIRE(r.contains("tracking"));
  CHECK(r["tracking"]["error"].get<std::string>().find("camera calibration failed") != std::string::npos);
  CHECK(r["markers"].size() == 5);  // the DEM truth is still there
}

TEST_CASE("chute: an outlet thinner than a clump jams and the run says so", "[experiment]") {
  auto o = soft({"pebble", "steel", "perspex"}, 1e6);
  o.push_back("particles.0.count=200");
  o.push_back("particles.0.region_max=[0.6, 0.3, 0.12]");
  o.push_back("experiment.tilt_steps=200");
  o.push_back("cameras.side.movie=false");
  o.push_back("cameras.side.frame_rate=10");
  const json r = runFor(std::string(ROCKLAB_SOURCE_DIR) + "/tests/experiments/scenes/narrow-chute.toml", o, "jam");
  CHECK(r["jammed"] == true);
  CHECK(r["clearance_time_s"].is_null());
  CHECK(r["chute"]["discharged_bodies"] == 0);
}

TEST_CASE("zoned chute: zones deposit - a column of markers per zone flows out - every clump kept or cut by the top plate", "[experiment]") {
  std::vector<std::string> o = soft({"small", "medium", "large", "steel_base", "perspex"}, 1e6);
  for (const char* s : {"particles.0.count=150", "particles.1.count=120", "particles.2.count=100",
                        "particles.0.region_max=[0.2, 0.3, 0.3]", "particles.1.region_max=[0.4, 0.3, 0.35]",
                        "particles.2.region_max=[0.6, 0.3, 0.4]", "experiment.tilt_steps=300"})
    o.push_back(s);
  const json r = runFor(kAssets + "zoned-chute.toml", o, "zoned");
  INFO(r.dump(2));
  const json& c = r["chute"];
  // Zones deposit: the three zones (150 + 120 + 100 clumps) come to rest behind
  // their temporary walls before the gate opens.
  CHECK(c["deposit_settled"] == true);
  REQUIRE(c["deposit_end_s"].is_number());
  REQUIRE(c["gate_open_s"].is_number());
  CHECK(c["gate_open_s"].get<double>() >= c["deposit_end_s"].get<double>());
  // The top plate: every clump is either kept or removed by it. (At this size and
  // bite the 370 clumps settle below the plate: the cut itself is the next test's.)
  const int removed = c["bodies_removed_by_top_plate"].get<int>();
  CHECK(c["bodies"].get<int>() + removed == 370);
  // Flows out: every remaining clump leaves through the outlet, and so does the
  // marker of each zone (its travel over the measuring distance is timed).
  CHECK(r["jammed"] == false);
  CHECK(r["clearance_time_s"].is_number());
  CHECK(c["discharged_bodies"] == c["bodies"]);
  REQUIRE(r["markers"].size() == 12);
  // One column of four markers per zone (zones 0-0.2, 0.2-0.4, 0.4-0.6 m from the
  // outlet), bottom up, at the middle of four equal layers of the channel height under
  // the top plate (CSS 50 mm + x tan 20 deg); the marker near the bed's bottom of each
  // zone is timed (the small test bed does not fill the channel: the upper targets
  // take the nearest clump, which may leave before the gate's flow reaches it).
  const double fractions[] = {0.125, 0.375, 0.625, 0.875};
  for (int k = 0; k < 12; ++k) {
    const json& m = r["markers"][k];
    const int zone = k / 4, row = k % 4;
    CHECK(m["column"] == zone + 1);
    CHECK(m["row"] == row + 1);
    const double x = m["lab_position_m"][0].get<double>(), z = m["lab_position_m"][2].get<double>();
    CHECK(x == Approx(0.1 + 0.2 * zone));
    CHECK(z == Approx(fractions[row] * (0.05 + x * std::tan(20.0 * M_PI / 180.0))).epsilon(1e-9));
    if (row == 0) CHECK(m["truth_velocity_mps"].is_number());
  }
  // A profile a zone: its measured markers' mean.
  REQUIRE(r["profile"].size() == 3);
  for (const auto& zone : r["profile"]) CHECK(zone["markers_measured"].get<int>() >= 1);
  CHECK(r["chute"]["deposit_inclination_deg"] == 45.0);
  CHECK(r["clump_shapes"].size() == 3);
}

TEST_CASE("zoned chute: the top plate cuts the deposited bed - what reached it goes, the rest stays below", "[experiment]") {
  // The plate lowered to a 3 deg bite (50 mm at the outlet, 81 mm at the feed end)
  // lies inside the small test bed, so the cut of §d DEM 3 really removes clumps.
  std::vector<std::string> o = soft({"small", "medium", "large", "steel_base", "perspex"}, 1e6);
  for (const char* s : {"particles.0.count=150", "particles.1.count=120", "particles.2.count=100",
                        "particles.0.region_max=[0.2, 0.3, 0.3]", "particles.1.region_max=[0.4, 0.3, 0.35]",
                        "particles.2.region_max=[0.6, 0.3, 0.4]", "experiment.tilt_steps=300", "walls.7.angle_deg=3.0"})
    o.push_back(s);
  const json r = runFor(kAssets + "zoned-chute.toml", o, "zoned-cut");
  const json& c = r["chute"];
  const int removed = c["bodies_removed_by_top_plate"].get<int>();
  CHECK(removed > 0);
  CHECK(c["bodies"].get<int>() + removed == 370);
  // The plate's lower face: z = 0.05 + x tan 3 deg. In the deposited bed (the last
  // frame before the cut) some balls reach it; in the first frame after it none does
  // (a ball left across the plate would stay there: the plate is a wall from then on).
  const double tan_bite = std::tan(3.0 * M_PI / 180.0);
  auto reaching = [&](const rocklab::sim::Snapshot& f) {
    std::set<std::int32_t> clumps;
    for (std::size_t i = 0; i < f.position.size(); ++i) {
      const double gap = 0.05 + f.position[i].x() * tan_bite - f.position[i].z();  // vertical gap to the plate
      if (gap * std::cos(3.0 * M_PI / 180.0) < f.radius[i] - 1e-3) clumps.insert(f.clump[i]);
    }
    return clumps.size();
  };
  rocklab::sim::output::RunFileReader file(fs::temp_directory_path() / "rocklab-exp-zoned-cut" / "run.h5");
  const double cut = c["deposit_end_s"].get<double>();
  std::size_t before = 0, after = 0;
  bool seen_after = false;
  for (std::size_t k = 0; k < file.frameCount() && !seen_after; ++k) {
    const rocklab::sim::Snapshot& f = file.frame(k);
    if (f.time < cut) {
      before = reaching(f);
    } else {
      after = reaching(f);
      CHECK(f.clump_position.size() == c["bodies"].get<std::size_t>());
      seen_after = true;
    }
  }
  REQUIRE(seen_after);
  CHECK(before >= static_cast<std::size_t>(removed) / 2);  // the bed did reach the plate (within 1 mm)
  CHECK(after == 0);
}

TEST_CASE("zoned chute: stopped in its deposit, at its end (stop_after) or in its flow and restarted, it ends as the straight run, bit for bit",
          "[experiment][restart]") {
  // The driver saves its phase, the deposit's and the gate's times, the markers and
  // the discharge so far; a restart rebuilds the model of that phase (gravity, the
  // zone walls gone, the top plate placed, the gate open) from the saved times.
  std::vector<std::string> o = soft({"small", "medium", "large", "steel_base", "perspex"}, 1e6);
  for (const char* s : {"particles.0.count=150", "particles.1.count=120", "particles.2.count=100",
                        "particles.0.region_max=[0.2, 0.3, 0.3]", "particles.1.region_max=[0.4, 0.3, 0.35]",
                        "particles.2.region_max=[0.6, 0.3, 0.4]", "experiment.tilt_steps=300",
                        "output.checkpoint=true", "output.frame_interval=0.1"})
    o.push_back(s);
  const fs::path dir = test::scratchDir("zoned-restart");
  const auto run = [&](const std::string& out, const std::string& end_time) {
    std::vector<std::string> args{"run", kAssets + "zoned-chute.toml", "--out", (dir / out).string(), "--threads", "1",
                                  "--quiet"};
    for (const std::string& s : o) args.insert(args.end(), {"--set", s});
    if (!end_time.empty()) args.insert(args.end(), {"--set", "scene.end_time=" + end_time});
    return test::cli(args);
  };
  const auto results = [&](const std::string& out) {
    std::ifstream in(dir / out / "results.json");
    return json::parse(in);
  };
  REQUIRE(run("straight", "") == 0);
  const json straight = results("straight");
  REQUIRE(straight["clearance_time_s"].is_number());
  const double deposit_end = straight["chute"]["deposit_end_s"].get<double>();
  const double gate = straight["chute"]["gate_open_s"].get<double>();
  const double flow_mid = gate + 0.5 * straight["clearance_time_s"].get<double>();
  for (const double stop : {0.6 * deposit_end, flow_mid}) {
    const std::string first = "to-" + std::to_string(stop), second = "from-" + std::to_string(stop);
    REQUIRE(run(first, std::to_string(stop)) == 0);
    if (stop > gate) CHECK(results(first)["chute"]["discharged_bodies"].get<int>() > 0);  // stopped mid-flow
    REQUIRE(test::cli({"restart", (dir / first / "checkpoint.h5").string(), "--out", (dir / second).string(),
                       "--threads", "2", "--quiet", "--set", "scene.end_time=8.0"}) == 0);
    const json restarted = results(second);
    INFO("stopped at t = " << stop << " s");
    CHECK(restarted["state_hash"] == straight["state_hash"]);
    CHECK(restarted["clearance_time_s"] == straight["clearance_time_s"]);
    CHECK(restarted["markers"] == straight["markers"]);
    CHECK(restarted["profile"] == straight["profile"]);
    for (const char* key : {"deposit_end_s", "gate_open_s", "bodies", "bodies_removed_by_top_plate",
                            "discharged_bodies", "discharged_mass_kg"})
      CHECK(restarted["chute"][key] == straight["chute"][key]);
    CHECK(test::slurp(dir / second / "discharge.csv") == test::slurp(dir / "straight" / "discharge.csv"));
  }
  // Stopped where its deposit is over (experiment.stop_after), before the plate is
  // placed: the checkpoint is the state the straight run placed its plate into, so a
  // sweep of plates restarted from it holds the straight run bit for bit, and a lower
  // plate (CSS 40 mm) cuts more of the same deposit.
  o.push_back("experiment.stop_after=\"deposit\"");
  // Without its checkpoint such a run would be lost: refused, naming both keys.
  try {
    loadScene(kAssets + "zoned-chute.toml", {"experiment.stop_after=\"deposit\""});
    FAIL("stop_after = \"deposit\" was accepted without output.checkpoint");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("experiment.stop_after") && Catch::Contains("output.checkpoint = true"));
  }
  REQUIRE(run("deposit", "") == 0);
  const json deposit = results("deposit");
  CHECK(deposit["chute"]["stopped_after_deposit"] == true);
  CHECK(deposit["chute"]["deposit_end_s"] == straight["chute"]["deposit_end_s"]);
  CHECK(deposit["chute"]["gate_open_s"].is_null());
  REQUIRE(test::cli({"sweep", (dir / "deposit" / "checkpoint.h5").string(), "--vary",
                     "walls.top.corner=[0,0,0.05],[0,0,0.04]", "--jobs", "0", "--threads", "2", "--quiet", "--out",
                     (dir / "plates").string(), "--set", "scene.end_time=8.0"}) == 0);
  CHECK_THAT(test::slurp(dir / "plates" / "runs.txt"), Catch::Contains(" restart "));  // each line a restart
  std::vector<json> plates;
  for (const auto& e : fs::directory_iterator(dir / "plates" / "runs")) {
    std::ifstream in(e.path() / "results.json");
    plates.push_back(json::parse(in));
  }
  REQUIRE(plates.size() == 2);
  std::sort(plates.begin(), plates.end(), [](const json& a, const json& b) {
    return a["chute"]["bodies"].get<int>() > b["chute"]["bodies"].get<int>();
  });
  const json& css50 = plates[0];
  const json& css40 = plates[1];
  CHECK(css50["state_hash"] == straight["state_hash"]);
  CHECK(css50["clearance_time_s"] == straight["clearance_time_s"]);
  CHECK(css50["markers"] == straight["markers"]);
  CHECK(css50["chute"]["stopped_after_deposit"] == false);
  CHECK(css40["chute"]["bodies_removed_by_top_plate"].get<int>() > straight["chute"]["bodies_removed_by_top_plate"].get<int>());
  CHECK(css40["chute"]["deposit_end_s"] == straight["chute"]["deposit_end_s"]);
  CHECK(css40["state_hash"] != straight["state_hash"]);
  // The sweep's table keeps a vary value with commas in one cell.
  CHECK_THAT(test::slurp(dir / "plates" / "sweep.csv"), Catch::Contains("\n\"[0,0,0.05]\","));
  // `rocklab profiles`: the two plates' markers side by side, the column means as each run reported them.
  std::vector<std::string> profile_args{"profiles"};
  for (const auto& e : fs::directory_iterator(dir / "plates" / "runs")) profile_args.push_back(e.path().string());
  profile_args.insert(profile_args.end(), {"--out", (dir / "profiles").string()});
  REQUIRE(test::cli(profile_args) == 0);
  std::ifstream pj(dir / "profiles" / "profiles.json");
  const json profiles = json::parse(pj);
  REQUIRE(profiles["runs"].size() == 2);
  for (const json& row : profiles["runs"]) {
    std::ifstream in(fs::path(row["run"].get<std::string>()) / "results.json");
    const json r = json::parse(in);
    CHECK(row["clearance_time_s"] == r["clearance_time_s"]);
    REQUIRE(row["columns"].size() == r["profile"].size());
    for (std::size_t c = 0; c < r["profile"].size(); ++c)
      CHECK(row["columns"][c]["mean_truth_velocity_mps"] == r["profile"][c]["mean_truth_velocity_mps"]);
  }
  const std::string rows = test::slurp(dir / "profiles" / "profiles.csv");
  CHECK(static_cast<std::size_t>(std::count(rows.begin(), rows.end(), '\n')) ==
        1 + css50["markers"].size() + css40["markers"].size());
  for (const char* png : {"profile_column_1.png", "profile_column_3.png", "discharge.png", "profiles.png"})
    CHECK(fs::file_size(dir / "profiles" / png) > 1000);
  // The columns side by side: every column's points, named by their panel.
  const std::string row_data = test::slurp(dir / "profiles" / "profiles.plot.csv");
  CHECK(static_cast<std::size_t>(std::count(row_data.begin(), row_data.end(), '\n')) ==
        1 + css50["markers"].size() + css40["markers"].size());
  CHECK_THAT(row_data, Catch::Contains("\n\"column 1, 100 mm from the outlet (DEM truth): "));
  // Not a chute run: exit 2, naming the file.
  CHECK(test::cli({"profiles", (dir / "plates").string(), "--out", (dir / "bad").string()}) == 2);
  CHECK_FALSE(fs::exists(dir / "bad"));
  fs::remove_all(dir);
}

TEST_CASE("chute: a run filmed for tracking is not restarted after its deposit, and says why", "[experiment][restart]") {
  // The tracker's frames are not in the checkpoint: a restart after the markers were
  // chosen would track half a flow. The checkpoint at the run's end is refused with
  // exit code 2, naming the camera; nothing is written.
  const fs::path dir = test::scratchDir("chute-tracked-restart");
  std::vector<std::string> args{"run", kAssets + "chute-30-clumps.toml", "--out", (dir / "first").string(), "--quiet"};
  auto o = soft({"pebble", "steel", "perspex"}, 1e6);
  for (const char* s : {"particles.0.count=150", "particles.0.region_max=[0.6, 0.3, 0.1]", "experiment.marker_heights=[0.01]",
                        "experiment.tilt_steps=200", "cameras.side.frame_rate=20", "cameras.side.movie=false",
                        "output.checkpoint=true"})
    o.push_back(s);
  for (const std::string& s : o) args.insert(args.end(), {"--set", s});
  REQUIRE(test::cli(args) == 0);
  std::string log;
  CHECK(test::cliLogged({"restart", (dir / "first" / "checkpoint.h5").string(), "--out", (dir / "second").string()},
                        log) == kExitBadInput);
  CHECK_THAT(log, Catch::Contains("tracks camera 'side'"));
  CHECK_FALSE(fs::exists(dir / "second" / "results.json"));
  fs::remove_all(dir);
}

TEST_CASE("a run that owns its scene frees the scene's particle lists and ends in the same state", "[experiment]") {
  // runScene(Scene&&) (the CLI's run, sweeps and run lists) drops the scene's spheres,
  // clumps and bonds once the World and the experiment hold them: the memory of a large
  // run (bench/run-bench.sh memory). The run must not notice.
  auto o = soft({"pebble", "steel", "perspex"}, 1e6);
  for (const char* s : {"particles.0.count=200", "particles.0.region_max=[0.6, 0.3, 0.12]", "experiment.tilt_steps=200",
                        "cameras.side.movie=false", "cameras.side.frame_rate=10"})
    o.push_back(s);
  const std::string path = std::string(ROCKLAB_SOURCE_DIR) + "/tests/experiments/scenes/narrow-chute.toml";
  const fs::path dir = test::scratchDir("owned-scene");
  std::ostringstream log;
  RunOptions options;
  options.progress = false;
  options.threads = 1;
  const Scene kept = loadScene(path, o);
  options.out_dir = dir / "kept";
  REQUIRE(runScene(kept, options, log) == kExitOk);
  Scene owned = loadScene(path, o);
  REQUIRE(owned.clumps.size() == 200);
  options.out_dir = dir / "owned";
  REQUIRE(runScene(std::move(owned), options, log) == kExitOk);
  CHECK(owned.clumps.empty());  // NOLINT(bugprone-use-after-move): the documented hand-back
  CHECK(owned.spheres.capacity() == 0);
  CHECK(kept.clumps.size() == 200);
  auto results = [&](const char* run) {
    std::ifstream in(dir / run / "results.json");
    return json::parse(in);
  };
  const json a = results("kept"), b = results("owned");
  CHECK(a["state_hash"] == b["state_hash"]);
  CHECK(a["jammed"] == b["jammed"]);
  CHECK(a["markers"] == b["markers"]);
  fs::remove_all(dir);
}

TEST_CASE("chute: the deposit ends when what the top plate keeps is at rest, or with settle_scope all when every ball is",
          "[experiment]") {
  // Nine spheres rest under the plate; a tenth falls from 2 m. Only the nine count
  // by default: the deposit ends at settle_min_time and the plate deletes the tenth.
  // With "all" it cannot end before the tenth has reached the base (0.64 s of fall).
  const std::string path = std::string(ROCKLAB_SOURCE_DIR) + "/tests/experiments/scenes/settle-scope-chute.toml";
  const json kept = runFor(path, {}, "settle-kept");
  CHECK(kept["chute"]["settle_scope"] == "kept");
  CHECK(kept["chute"]["deposit_settled"] == true);
  CHECK(kept["chute"]["deposit_end_s"].get<double>() < 0.2);
  CHECK(kept["chute"]["bodies_removed_by_top_plate"] == 1);
  CHECK(kept["chute"]["discharged_bodies"] == 9);
  const json all = runFor(path, {"experiment.settle_scope=\"all\""}, "settle-all");
  CHECK(all["chute"]["settle_scope"] == "all");
  CHECK(all["chute"]["deposit_end_s"].get<double>() > 0.6);
  // A bad value names the key and what is allowed.
  try {
    loadScene(path, {"experiment.settle_scope=\"some\""});
    FAIL("settle_scope = \"some\" was accepted");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("settle_scope") && Catch::Contains("kept"));
  }
}
