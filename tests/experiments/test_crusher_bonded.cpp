// The crusher's bonded feed (experiments.md §g.7): agglomerates placed at random in a
// box (each its size class's agglomerate scaled to its own diameter), discharged by
// fragments (balls joined by intact bonds) sized by Eq 6-15, and strong bonds while
// the feed settles on the stop wall. Small free-fall scenes, no chamber: a few
// seconds of CI.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.h"
#include "rocklab/experiments/scene.h"

namespace fs = std::filesystem;
using namespace rocklab::experiments;

namespace {

// Two HCP agglomerates of 24-28 mm (19 balls of 3.5 mm at 28 mm) over a drop, soft
// linear contacts and bonds (a coarse step); `extra` is appended (walls, sources).
std::string feedScene(const std::string& particles, const std::string& extra, double strength) {
  std::ostringstream s;
  s << "[scene]\nname = \"bonded-feed\"\nseed = 1\nend_time = 0.8\n"
    << "[materials.rock]\ndensity = 2650\nkn = 1e6\nks = 1e6\nfriction = 0.5\n"
    << "[contact]\nlaw = \"linear\"\ndamping_normal = 0.3\ndamping_shear = 0.3\n"
    << "[bonds]\nradius_multiplier = 1.0\nnormal_stiffness = 1e10\nshear_stiffness = 4e9\n"
    << "tensile_strength = " << strength << "\nfailure_rule = \"stress\"\n"
    << "[gravity]\nvector = [0, 0, -9.81]\n"
    << "[timestep]\nsafety_factor = 0.2\n"
    << particles << extra
    << "[experiment]\ntype = \"crusher\"\ndischarge_height = -0.1\nsample_interval = 0.001\n"
    << "[output]\nvtk = false\ncheckpoint = false\n";
  return s.str();
}

std::string agglomerates(int count, const std::string& z_min, const std::string& z_max, const std::string& x_min = "-0.05",
                         const std::string& x_max = "0.05", const std::string& velocity = "[0, 0, 0]") {
  return "[[particles]]\ntype = \"agglomerates\"\nmaterial = \"rock\"\ncount = " + std::to_string(count) +
         "\ndiameter_min = 0.024\ndiameter_max = 0.028\nmethod = \"hcp\"\nradius = 0.0035\ntemplates = 2\n"
         "region_min = [" + x_min + ", -0.02, " + z_min + "]\nregion_max = [" + x_max + ", 0.02, " + z_max +
         "]\nvelocity = " + velocity + "\n";
}

const std::string kStopWall =
    "[[walls]]\ntype = \"plane\"\nname = \"crusher.stop\"\npoint = [0, 0, 0]\nnormal = [0, 0, 1]\n"
    "material = \"rock\"\nactive_until = 0.4\n";

/// Runs `scene_text` (written to a scratch folder) with `sets`; results.json.
/// `inspect` sees the run's folder before it is removed.
nlohmann::json run(const std::string& name, const std::string& scene_text, const std::vector<std::string>& sets = {},
                   const std::function<void(const fs::path&)>& inspect = {}) {
  const fs::path dir = test::scratchDir("bonded-" + name);
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml") << scene_text;
  std::vector<std::string> args{"run", (dir / "scene.toml").string(), "--out", (dir / "out").string(), "--threads", "1",
                                "--quiet"};
  for (const std::string& s : sets) args.insert(args.end(), {"--set", s});
  REQUIRE(test::cli(args) == 0);
  std::ifstream in(dir / "out" / "results.json");
  nlohmann::json r = nlohmann::json::parse(in);
  std::ifstream csv(dir / "out" / "product.csv");
  std::string line;
  std::getline(csv, line);
  for (; std::getline(csv, line);) {
    std::vector<double> v;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) v.push_back(std::stod(cell));
    r["product_rows"].push_back(v);  // id, time_s, diameter_mm, mass_kg, residence_s
  }
  if (inspect) inspect(dir / "out");
  fs::remove_all(dir);
  return r;
}

}  // namespace

TEST_CASE("an agglomerate feed: uniform diameters, one structure a class scaled, no overlap", "[crusher][bonds]") {
  const Scene scene =
      loadSceneText(feedScene(agglomerates(6, "0.0", "0.2"), "", 1e9), "feed.toml", {}, fs::temp_directory_path());
  REQUIRE(scene.agglomerates.size() == 6);
  std::size_t balls = 0, bonds = 0;
  for (const AgglomerateReport& a : scene.agglomerates) {
    CHECK(a.diameter >= 0.024);
    CHECK(a.diameter <= 0.028);
    CHECK(a.balls >= 13);  // the centre and its twelve neighbours at least
    CHECK(a.first_ball == balls);
    balls += a.balls;
    bonds += a.bonds;
    // No two of its balls reach further apart than its diameter: the template scaled, not cut.
    double span = 0;
    for (std::size_t i = a.first_ball; i < a.first_ball + a.balls; ++i)
      for (std::size_t k = a.first_ball; k < a.first_ball + a.balls; ++k)
        span = std::max(span, (scene.spheres[i].position - scene.spheres[k].position).norm() + scene.spheres[i].radius +
                                  scene.spheres[k].radius);
    CHECK(span <= a.diameter * (1 + 1e-9));
  }
  CHECK(balls == scene.spheres.size());
  CHECK(bonds == scene.bonds.size());
  // Two classes (24-26, 26-28 mm): within a class the same structure, so the same
  // counts and porosity; sizes differ (uniform draws).
  for (const AgglomerateReport& a : scene.agglomerates)
    for (const AgglomerateReport& b : scene.agglomerates) {
      if ((a.diameter < 0.026) != (b.diameter < 0.026)) continue;
      CHECK(a.balls == b.balls);
      CHECK(a.bonds == b.bonds);
      CHECK(a.porosity == Approx(b.porosity).epsilon(1e-12));
    }
  CHECK(scene.agglomerates[0].diameter != scene.agglomerates[1].diameter);
}

TEST_CASE("a bonded crusher feed is discharged by fragments sized by Eq 6-15, mass kept", "[crusher][bonds]") {
  const double rho = 2650;
  SECTION("strong bonds: each agglomerate falls through whole, its Eq 6-15 size its own diameter") {
    const nlohmann::json r = run("whole", feedScene(agglomerates(2, "0.0", "0.03"), "", 1e9));
    const auto& c = r["crusher"];
    CHECK(c["empty"] == true);
    CHECK(c["discharged_balls"] == 2);  // two fragments, not 38 balls
    CHECK(c["bonded"]["single_balls_discharged"] == 0);
    CHECK(c["discharged_mass_kg"].get<double>() == Approx(c["feed_mass_kg"].get<double>()).epsilon(1e-14));
    // A whole agglomerate's Eq 6-15 size is its own diameter (24-28 mm).
    const auto& rows = r["product_rows"];
    REQUIRE(rows.size() == 2);
    for (const auto& row : rows) {
      const double d = row[2].get<double>() * 1e-3;
      CHECK(d >= 0.024);
      CHECK(d <= 0.028);
    }
  }
  SECTION("colliding at 8 m/s with weak bonds: fragments, each by Eq 6-15, mass kept") {
    const std::string two = agglomerates(1, "0.0", "0.03", "-0.05", "-0.015", "[4, 0, 0]") +
                            agglomerates(1, "0.0", "0.03", "0.015", "0.05", "[-4, 0, 0]");
    // `rocklab products` counts a bonded run's breakage by its bonds.
    nlohmann::json compared;
    const nlohmann::json r = run("collide", feedScene(two, "", 2e5), {"scene.end_time=1.5"}, [&](const fs::path& out) {
      const fs::path products = out / "products";
      REQUIRE(test::cli({"products", out.string(), "--out", products.string()}) == 0);
      std::ifstream in(products / "products.json");
      compared = nlohmann::json::parse(in)["runs"][0];
    });
    const auto& c = r["crusher"];
    CHECK(compared["feed"] == "bonded agglomerates (Eq 6-15 sizes)");
    CHECK(compared["bonds_broken"].get<long>() ==
          c["bonded"]["bonds"].get<long>() - c["bonded"]["bonds_intact_at_end"].get<long>());
    CHECK(compared["bonds_broken"].get<long>() > 0);
    CHECK(compared["discharged_fraction"].get<double>() == Approx(1.0).epsilon(1e-12));
    const double porosity = c["bonded"]["porosity_mean"].get<double>();
    CHECK(c["empty"] == true);
    CHECK(c["discharged_balls"].get<int>() > 2);  // they broke
    CHECK(c["discharged_mass_kg"].get<double>() == Approx(c["feed_mass_kg"].get<double>()).epsilon(1e-14));
    for (const auto& row : r["product_rows"]) {
      // Eq 6-15: R_f = [3 M / (4 pi rho (1 - P))]^(1/3)
      const double mass = row[3].get<double>();
      const double expected = 2 * std::cbrt(3 * mass / (4 * std::numbers::pi * rho * (1 - porosity)));
      CHECK(row[2].get<double>() * 1e-3 == Approx(expected).epsilon(1e-9));
    }
  }
}

TEST_CASE("settle_bond_factor keeps a feed whole on the stop wall and gives the bonds back when it goes",
          "[crusher][bonds]") {
  // Dropped 0.2 m onto the stop wall, bonds of 20 kPa break on landing; 10,000 times
  // as strong they hold until the wall goes at 0.4 s, and then, their strength back,
  // break under what the landing left in them.
  const std::string scene = feedScene(agglomerates(2, "0.2", "0.23"), kStopWall, 2e4);
  const nlohmann::json weak = run("weak", scene, {"scene.end_time=0.39"});
  const nlohmann::json held = run("held", scene, {"scene.end_time=0.39", "experiment.settle_bond_factor=10000"});
  const int bonds = held["crusher"]["bonded"]["bonds"].get<int>();
  CHECK(held["crusher"]["bonded"]["bonds_intact_at_end"].get<int>() == bonds);
  CHECK(weak["crusher"]["bonded"]["bonds_intact_at_end"].get<int>() < bonds / 2);
  const nlohmann::json released = run("released", scene, {"experiment.settle_bond_factor=10000"});
  const auto& b = released["crusher"]["bonded"];
  CHECK(b["strengths_restored_s"].get<double>() == Approx(0.4).margin(2e-5));
  CHECK(b["bonds_intact_at_release"].get<int>() == bonds);
  CHECK(released["crusher"]["discharged_balls"].get<int>() > 2);  // the restored strengths let them break

  // Without a stop wall the factor has nothing to end it: bad input, named.
  std::string log;
  const fs::path dir = test::scratchDir("bonded-nowall");
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml") << feedScene(agglomerates(2, "0.2", "0.23"), "", 2e4);
  CHECK(test::cliLogged({"check", (dir / "scene.toml").string(), "--set", "experiment.settle_bond_factor=10"}, log) == 2);
  CHECK(log.find("settle_bond_factor") != std::string::npos);
  CHECK(log.find("crusher.stop") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("a bonded crusher feed restarted while its bonds are held strong ends as the straight run, bit for bit",
          "[crusher][bonds][restart]") {
  // The checkpoint at 0.3 s holds the strengthened bonds and the strengths to give
  // back when the stop wall goes at 0.4 s: the restart must give them back and break
  // the feed as the run that went straight through.
  const fs::path dir = test::scratchDir("bonded-restart");
  fs::create_directories(dir);
  std::string scene = feedScene(agglomerates(2, "0.2", "0.23"), kStopWall, 2e4);
  scene.replace(scene.find("checkpoint = false"), 18, "checkpoint = true");
  std::ofstream(dir / "scene.toml") << scene;
  const auto runTo = [&](const std::string& out, const std::string& end) {
    return test::cli({"run", (dir / "scene.toml").string(), "--out", (dir / out).string(), "--threads", "1", "--quiet",
                      "--set", "experiment.settle_bond_factor=10000", "--set", "scene.end_time=" + end});
  };
  REQUIRE(runTo("straight", "0.8") == 0);
  REQUIRE(runTo("first", "0.3") == 0);
  REQUIRE(test::cli({"restart", (dir / "first" / "checkpoint.h5").string(), "--out", (dir / "second").string(),
                     "--quiet", "--set", "scene.end_time=0.8"}) == 0);
  const auto results = [&](const std::string& out) {
    std::ifstream in(dir / out / "results.json");
    return nlohmann::json::parse(in);
  };
  const nlohmann::json straight = results("straight"), second = results("second");
  CHECK(straight["crusher"]["discharged_balls"].get<int>() > 2);  // it broke after the release
  CHECK(second["state_hash"] == straight["state_hash"]);
  CHECK(second["crusher"] == straight["crusher"]);  // no moving wall: the power is 0 in both
  CHECK(test::slurp(dir / "second" / "product.csv") == test::slurp(dir / "straight" / "product.csv"));
  fs::remove_all(dir);
}
