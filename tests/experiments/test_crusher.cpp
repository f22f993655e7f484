// The cone crusher's scene table ([crusher]) and `rocklab crusher-geometry`.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "cli_support.h"
#include "crusher_support.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/geometry/mantle_motion.h"
#include "rocklab/sim/wall_motion.h"

namespace fs = std::filesystem;
using namespace rocklab::experiments;
using Catch::Matchers::Contains;

namespace {

const std::string kCrusherScene = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/cone-crusher.toml";

std::string loadError(const std::vector<std::string>& overrides) {
  try {
    loadScene(kCrusherScene, overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "loaded";
}

}  // namespace

TEST_CASE("[crusher] builds the Table 6.1 chamber as mesh walls and refuses bad geometry by key", "[scene][crusher]") {
  const Scene s = loadScene(kCrusherScene);
  REQUIRE(s.crusher);
  CHECK(s.crusher->spec.css == 0.015);
  CHECK(s.crusher->spec.bite_angle_deg == 20.0);
  CHECK(s.crusher->eccentric_rpm == 300.0);
  CHECK(s.crusher->spin_sense == rocklab::geometry::SpinSense::Opposite);
  REQUIRE(s.model.walls.size() == 4);
  CHECK(s.wall_looks.size() == 4);
  CHECK(s.model.walls[0].name == "crusher.mantle");
  CHECK(s.model.walls[3].name == "crusher.upper_concave");
  for (const auto& w : s.model.walls) {
    CHECK(w.shape == rocklab::sim::WallShape::Mesh);
    CHECK(w.mesh.validate().empty());
    CHECK(w.smooth_angle_deg == 10.0);  // the 96 facets meet at 3.75 degrees: one smooth surface
  }
  // A coarser tessellation is still one smooth surface: at least 1.5 x its facets' angle.
  for (const auto& w : loadScene(kCrusherScene, {"crusher.segments=24"}).model.walls)
    CHECK(w.smooth_angle_deg == Approx(22.5));
  // The mantle and its cap gyrate and spin; the concaves stay.
  CHECK(!s.model.walls[0].motion.isStatic());
  CHECK(!s.model.walls[1].motion.isStatic());
  CHECK(s.model.walls[2].motion.isStatic());
  CHECK(s.model.walls[3].motion.isStatic());
  CHECK(loadScene(kCrusherScene, {"crusher.eccentric_speed_rpm=0"}).model.walls[0].motion.isStatic());
  CHECK(loadScene(kCrusherScene, {"crusher.walls=false"}).model.walls.empty());
  CHECK(loadScene(kCrusherScene, {"crusher.pivot=\"eq6-1\""}).crusher->spec.pivot ==
        rocklab::geometry::PivotPlacement::Eq61);

  CHECK_THAT(loadError({"crusher.css=0.06"}),
             Contains("--set crusher.css=0.06") && Contains("css (CSS) = 60 mm: must be less than the feed opening F = 55 mm"));
  CHECK_THAT(loadError({"crusher.bite_angle_deg=-5"}), Contains("crusher.bite_angle_deg"));
  CHECK_THAT(loadError({"crusher.feed_opening=0.2"}),
             Contains("crusher.bite_angle_deg") && Contains("R_top_c = "));
  CHECK_THAT(loadError({"crusher.spin_sense=\"backwards\""}), Contains("opposite"));
}

TEST_CASE("crusher-geometry prints, draws the section and writes results.json, and a scene without [crusher] is bad input",
          "[cli][crusher]") {
  const fs::path out = fs::temp_directory_path() / ("rocklab-crusher-" + std::to_string(::getpid()));
  fs::remove_all(out);
  REQUIRE(test::cli({"crusher-geometry", kCrusherScene, "--out", out.string(), "--set", "crusher.css=0.012",
                     "--set", "crusher.bite_angle_deg=18"}) == 0);
  CHECK(fs::file_size(out / "section.png") > 1000);
  std::ifstream in(out / "results.json");
  const auto r = nlohmann::json::parse(in);
  CHECK(r["readings"]["pivot"] == "axis");
  CHECK(r["readings"]["mantle_top_x"] == "corrected");
  const auto& q = r["quantities"];
  CHECK(q["R_top_c_mm"].get<double>() == Approx(58.56).margin(0.01));  // §g.2's worked row 12 mm, 18 deg
  CHECK(q["R_top_m_mm"].get<double>() == Approx(20.45).margin(0.01));
  CHECK(q["h_eq61_mm"].get<double>() == Approx(64.46).margin(0.01));
  CHECK(q["net_mantle_rotation_rpm"].get<double>() == Approx(-9.0).margin(1e-9));
  CHECK(q["open_side_setting_mm"].get<double>() > q["closed_side_gap_mm"].get<double>());
  CHECK(r["mesh_triangles"]["mantle"] == 192);

  const fs::path out2 = out / "none";
  CHECK(test::cli({"crusher-geometry", std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/drop.toml", "--out",
                   out2.string()}) == 2);
  CHECK(!fs::exists(out2));
  CHECK(test::cli({"crusher-geometry", kCrusherScene, "--out", out2.string(), "--set", "crusher.css=0.06"}) == 2);
  CHECK(!fs::exists(out2));
  fs::remove_all(out);
}

TEST_CASE("the crusher's mantle wall: gyration in the pose, Eq 6-9 spin in the velocity only, no drift", "[scene][crusher]") {
  using rocklab::geometry::Vec3;
  const Scene s = loadScene(kCrusherScene);
  const rocklab::sim::WallMotion& motion = s.model.walls[0].motion;
  const auto g = rocklab::geometry::coneCrusherGeometry(s.crusher->spec);
  const auto m = rocklab::geometry::mantleMotion(g, s.crusher->eccentric_rpm, s.crusher->spin_sense);
  const double period = 2 * std::numbers::pi / m.eccentric_speed;
  const Vec3 edge0 = g.mantle_bottom_edge.world();
  const double rim_speed = m.eccentric_speed * g.R_bot_m;

  // The engine's wall velocity is the reference's field (two rigid rotations), at
  // any point and time; the closed-side bottom edge, carried round by the
  // gyration, rolls (Eq 6-9: to 0.052 % of omega_ecc R, see docs/crusher.md).
  for (const double t : {0.0, 0.013, 0.37, 5.002}) {
    const rocklab::sim::WallPose pose = rocklab::sim::wallPoseAt(motion, t);
    for (const Vec3& x : {Vec3(0.1, 0.02, 0.05), Vec3(-0.12, 0.07, 0.09), edge0}) {
      const Vec3 expected = rocklab::geometry::mantleVelocityAt(m, t, x);
      CHECK((pose.velocityAt(x) - expected).norm() < 1e-9 * rim_speed);
    }
    CHECK(pose.velocityAt(pose.place(edge0)).norm() < 6e-4 * rim_speed);
  }
  // With the spin in the same sense the edge slides at about twice the rim speed.
  const Scene same = loadScene(kCrusherScene, {"crusher.spin_sense=\"same\""});
  const auto same_pose = rocklab::sim::wallPoseAt(same.model.walls[0].motion, 0.01);
  CHECK(same_pose.velocityAt(same_pose.place(edge0)).norm() > 1.9 * rim_speed);

  // After whole gyrations every mantle vertex is back where it started: the spin
  // (which would turn it by -N 2 pi e/R) is not in the pose and the angle is
  // reduced to one turn.
  for (const int revolutions : {1, 1000, 100000}) {
    const rocklab::sim::WallPose pose = rocklab::sim::wallPoseAt(motion, revolutions * period);
    double worst = 0;
    for (const Vec3& v : s.model.walls[0].mesh.vertices) worst = std::max(worst, (pose.place(v) - v).norm());
    CHECK(worst < 1e-9);
  }
  // Half a gyration puts the closed-side edge on the open side.
  const Vec3 half = rocklab::sim::wallPoseAt(motion, 0.5 * period).place(edge0);
  CHECK(half.x() == Approx(-edge0.x()).margin(1e-12));
}

TEST_CASE("a tiny crusher run: the feed falls from the bin through the moving chamber and is discharged", "[cli][crusher]") {
  // The PBM scene with six 8-9 mm spheres (crusher_support.h): every ball must
  // reach the discharge below the chamber, its size recorded, and the run end
  // there (the chamber is empty). The walls' ParaView series shows the mantle at
  // its pose.
  const fs::path out = test::scratchDir("crusher-run");
  REQUIRE(test::cli(test::tinyCrusherRunArgs(out.string())) == 0);
  std::ifstream in(out / "results.json");
  const auto r = nlohmann::json::parse(in);
  CHECK(r["experiment"] == "crusher");
  CHECK(!r.contains("experiment_status"));  // ended by the empty chamber, not by end_time
  // Bodies at the start and at the end (all discharged), both on the page.
  CHECK(r["particles_at_start"] == 6);
  CHECK(r["particles"] == 0);
  const std::string page = test::slurp(out / "report.html");
  CHECK(page.find("<td>particles (balls) / clumps at the start</td><td>6 / 0</td>") != std::string::npos);
  const auto& c = r["crusher"];
  INFO(c.dump());
  CHECK(c["feed_balls"] == 6);
  CHECK(c["discharged_balls"] == 6);
  CHECK(c["empty"] == true);
  CHECK(c["discharged_mass_kg"].get<double>() == Approx(c["feed_mass_kg"].get<double>()).epsilon(1e-12));
  CHECK(c["first_discharge_s"].get<double>() > 0.1);  // not before the stop wall went and the fall
  const auto& psd = c["psd"];
  CHECK(psd.front()["passing"] == 0.0);  // 2 mm: nothing finer
  CHECK(psd.back()["passing"] == 1.0);   // 31.5 mm: everything
  // Every ball discharged whole: the product's curve is the feed's, and both are drawn.
  CHECK(c["feed_psd"] == psd);
  CHECK(fs::exists(out / "product_size.png"));
  const std::string product = test::slurp(out / "product.csv");
  CHECK(std::count(product.begin(), product.end(), '\n') == 7);  // header + 6 balls
  // The product statistics: P50 <= P80 within the feed's 8-9 mm; every ball seen
  // entering the chamber, its residence shorter than the run; the mantle did work.
  CHECK(c["p50_mm"].get<double>() >= 8.0);
  CHECK(c["p50_mm"].get<double>() <= c["p80_mm"].get<double>());
  CHECK(c["p80_mm"].get<double>() <= 9.0);
  CHECK(c["residence_s"]["balls"] == 6);
  CHECK(c["residence_s"]["mean"].get<double>() > 0);
  CHECK(c["residence_s"]["max"].get<double>() < c["last_discharge_s"].get<double>());
  CHECK(c["throughput_tph"].get<double>() > 0);
  CHECK(c["power"]["energy_J"].get<double>() > 0);
  CHECK(c["power_W"] == c["power"]["power_W"]);
  CHECK(c["breakages"] == 0);
  CHECK(fs::exists(out / "mantle_power.png"));
  // `rocklab whiten` on the run: k1 above every ball selects none (the product is
  // the feed); k1, k2 across the feed's 8-9 mm break some, mass kept; bad values and
  // a folder without a crusher run are bad input.
  const fs::path whiten = test::scratchDir("crusher-run-whiten");
  REQUIRE(test::cli({"whiten", out.string(), "--k1-mm", "30", "--k2-mm", "40", "--out", whiten.string()}) == 0);
  {
    std::ifstream w_in(whiten / "whiten.json");
    const auto w = nlohmann::json::parse(w_in);
    CHECK(w["passing"] == c["feed_psd"]);
  }
  REQUIRE(test::cli({"whiten", out.string(), "--k1-mm", "4", "--k2-mm", "8.5", "--out", whiten.string()}) == 0);
  {
    std::ifstream w_in(whiten / "whiten.json");
    const auto w = nlohmann::json::parse(w_in);
    CHECK(w["passing"][3]["passing"].get<double>() > 0);  // finer than 8 mm now: broken pieces
    CHECK(std::abs(w["mass_balance_relative"].get<double>()) < 1e-14);
  }
  CHECK(fs::exists(whiten / "whiten.png"));
  CHECK(test::cli({"whiten", out.string(), "--k1-mm", "9", "--k2-mm", "8"}) == 2);
  CHECK(test::cli({"whiten", whiten.string()}) == 2);  // no results.json there
  // `rocklab products`: the run's curve and figures in the table as results.json has
  // them; a folder without a crusher run, a damaged curve, or labels that are not one
  // a run are bad input, and nothing is written.
  const fs::path products = test::scratchDir("crusher-run-products");
  REQUIRE(test::cli({"products", out.string(), out.string(), "--label", "first", "--label", "second", "--out",
                     products.string()}) == 0);
  {
    std::ifstream p_in(products / "products.json");
    const auto p = nlohmann::json::parse(p_in);
    REQUIRE(p["runs"].size() == 2);
    CHECK(p["runs"][1]["label"] == "second");
    CHECK(p["runs"][0]["psd"] == c["psd"]);
    CHECK(p["runs"][0]["p80_mm"] == c["p80_mm"]);
    CHECK(p["runs"][0]["feed"] == "spheres");
    CHECK(p["runs"][0]["discharged_fraction"].get<double>() == Approx(1.0).epsilon(1e-12));
    CHECK(p["runs"][0]["bonds_broken"].is_null());  // spheres: no bonds
    CHECK(p["runs"][0]["legend"] == "first");       // emptied: the label alone
    const std::string table = test::slurp(products / "products.csv");
    CHECK(std::count(table.begin(), table.end(), '\n') == 3);  // header + 2 runs
    CHECK(fs::exists(products / "product_curves.png"));
  }
  const fs::path damaged = test::scratchDir("crusher-run-damaged");
  fs::create_directories(damaged);
  {
    std::ifstream r_in(out / "results.json");
    auto bad = nlohmann::json::parse(r_in);
    bad["crusher"]["psd"][2]["passing"] = 1.5;
    std::ofstream(damaged / "results.json") << bad.dump();
  }
  // A run stopped before its chamber emptied says so in the chart's legend, with
  // how much of its feed its curve holds.
  const fs::path partial = test::scratchDir("crusher-run-partial");
  fs::create_directories(partial);
  {
    std::ifstream r_in(out / "results.json");
    auto cut = nlohmann::json::parse(r_in);
    cut["crusher"]["empty"] = false;
    cut["crusher"]["discharged_mass_kg"] = 0.25 * cut["crusher"]["feed_mass_kg"].get<double>();
    cut["simulated_time_s"] = 1.5;
    std::ofstream(partial / "results.json") << cut.dump();
  }
  REQUIRE(test::cli({"products", out.string(), partial.string(), "--out", products.string()}) == 0);
  {
    std::ifstream p_in(products / "products.json");
    const auto p = nlohmann::json::parse(p_in);
    CHECK(p["runs"][1]["discharged_fraction"].get<double>() == Approx(0.25).epsilon(1e-12));
    CHECK(p["runs"][1]["legend"] == p["runs"][1]["label"].get<std::string>() +
                                        " (not empty: 25 % of the feed by t = 1.50 s)");
  }
  fs::remove_all(partial);
  const fs::path nothing = test::scratchDir("crusher-run-products-bad");
  std::string log;
  CHECK(test::cliLogged({"products", out.string(), damaged.string(), "--out", nothing.string()}, log) == 2);
  CHECK_THAT(log, Catch::Contains("crusher.psd") && Catch::Contains("passing within 0 and 1"));
  CHECK(test::cli({"products", out.string(), whiten.string(), "--out", nothing.string()}) == 2);
  CHECK(test::cli({"products", out.string(), "--label", "a", "--label", "b", "--out", nothing.string()}) == 2);
  CHECK_FALSE(fs::exists(nothing));
  fs::remove_all(products);
  fs::remove_all(damaged);
  fs::remove_all(whiten);
  CHECK(fs::exists(out / "vtk/walls.pvd"));
  CHECK(fs::exists(out / "vtk/walls_000001.vtp"));
  fs::remove_all(out);
}
