// The Zwick crushing test (experiments.md §e, §f) on a small HCP agglomerate,
// and the scene's agglomerate and [bonds] tables.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "agglomerate/agglomerate_library.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/geometry/bond_pairs.h"
#include "rocklab/geometry/hcp_packing.h"

namespace fs = std::filesystem;
using namespace rocklab::experiments;
using json = nlohmann::json;

namespace {

const std::string kZwick = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/zwick-hcp.toml";

/// A 16 mm agglomerate (dozens of spheres) closed 6x faster than Table 5.2: seconds, not minutes.
const std::vector<std::string> kSmall = {
    "particles.0.diameter=0.016", "particles.0.position=[0,0,0.009]",
    "experiment.platen_speed=0.05", "experiment.sample_interval=1e-5"};

std::string sceneError(const std::vector<std::string>& overrides) {
  try {
    loadScene(kZwick, overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("zwick: a small bonded agglomerate shows a peak and a drop, and loses no mass",
          "[experiment][zwick]") {
  const Scene scene = loadScene(kZwick, kSmall);
  REQUIRE(scene.agglomerates.size() == 1);
  REQUIRE(scene.bonds.size() == scene.agglomerates[0].bonds);
  CHECK(scene.agglomerates[0].coordination_number > 4);
  const fs::path dir = fs::temp_directory_path() / "rocklab-zwick-small";
  fs::remove_all(dir);
  RunOptions options;
  options.out_dir = dir;
  options.threads = 2;
  options.progress = false;
  std::ostringstream log;
  REQUIRE(runScene(scene, options, log) == kExitOk);
  INFO(log.str());
  std::ifstream in(dir / "results.json");
  const json r = json::parse(in);
  const json& z = r["zwick"];
  CHECK(z["failed"].get<bool>());
  const double peak = r["peak_force_N"].get<double>();
  CHECK(peak > 100.0);
  CHECK(r["bonds_broken"].get<std::size_t>() > 0);
  CHECK(r["sphere_count"].get<std::size_t>() == scene.spheres.size());
  // Eq 5-1 from the reported peak and gap.
  const double gap = z["platen_gap_at_peak_m"].get<double>();
  CHECK(r["strength_MPa"].get<double>() == Approx(peak / (gap * gap) * 1e-6));
  CHECK(gap < z["specimen_height_m"].get<double>());
  // The curve: rises to the peak, then drops below half of it (the test's end).
  std::ifstream csv(dir / "force_displacement.csv");
  std::string line;
  std::getline(csv, line);
  double last_force = 0, max_force = 0;
  while (std::getline(csv, line)) {
    std::stringstream row(line);
    std::string cell;
    for (int c = 0; c < 4; ++c) std::getline(row, cell, ',');
    last_force = std::stod(cell);
    max_force = std::max(max_force, last_force);
  }
  CHECK(max_force == Approx(peak));
  CHECK(last_force < 0.5 * peak);
  // Fragments share out the whole volume: nothing is lost.
  const json& f = r["fragments"];
  CHECK(f["largest_fraction"].get<double>() < 2.0 / 3.0);
  CHECK(f["count"].get<std::size_t>() > 1);
  CHECK(fs::exists(dir / "force_displacement.png"));
  CHECK(fs::exists(dir / "bond_breaks.csv"));
}

TEST_CASE("zwick: bonds of constant or Weibull strength - bad bond and platen keys are refused",
          "[experiment][zwick]") {
  const Scene constant = loadScene(kZwick, kSmall);
  for (const auto& b : constant.bonds) CHECK(b.tensile_strength == 60e6);
  const Scene per_agglomerate = loadScene(
      kZwick,
      {"bonds.strength_distribution=\"weibull_per_agglomerate\"", "bonds.weibull_modulus=3"});
  const double drawn = per_agglomerate.bonds.front().tensile_strength;
  CHECK(drawn != 60e6);
  for (const auto& b : per_agglomerate.bonds) CHECK(b.tensile_strength == drawn);
  CHECK(per_agglomerate.agglomerates[0].bond_strength == drawn);
  const Scene per_bond = loadScene(
      kZwick, {"bonds.strength_distribution=\"weibull_per_bond\"", "bonds.weibull_modulus=3"});
  CHECK(per_bond.bonds[0].tensile_strength != per_bond.bonds[1].tensile_strength);
  // Seeded: the same scene gives the same draws.
  CHECK(loadScene(kZwick,
                  {"bonds.strength_distribution=\"weibull_per_bond\"", "bonds.weibull_modulus=3"})
            .bonds[5]
            .tensile_strength == per_bond.bonds[5].tensile_strength);

  CHECK_THAT(sceneError({"bonds.normal_stiffness=-1"}), Catch::Contains("bonds.normal_stiffness"));
  CHECK_THAT(sceneError({"bonds.strength_distribution=\"weibull_per_bond\""}),
             Catch::Contains("weibull_modulus"));
  CHECK_THAT(sceneError({"bonds.weibull_modulus=3"}),
             Catch::Contains("only with strength_distribution"));
  CHECK_THAT(sceneError({"experiment.top_platen=\"lid\""}),
             Catch::Contains("no wall called 'lid'"));
  CHECK_THAT(sceneError({"particles.0.hcp_angle=120"}), Catch::Contains("hcp_angle"));
  CHECK_THAT(sceneError({"particles.0.diameter=0.004"}), Catch::Contains("two sphere radii"));
}

TEST_CASE("zwick: [bonds] type gives contact bonds (strengths in N) - keys of the other kind are refused",
          "[experiment][zwick][bonds]") {
  auto small = [](std::vector<std::string> keys) {
    keys.insert(keys.end(), kSmall.begin(), kSmall.end());
    return keys;
  };
  const std::size_t pairs = loadScene(kZwick, kSmall).bonds.size();
  REQUIRE(pairs > 0);
  // Both: the parallel bonds first (the agglomerate's range), then a contact bond per pair.
  const Scene both = loadScene(kZwick, small({"bonds.type=\"parallel+contact\"",
                                              "bonds.contact_normal_strength=40",
                                              "bonds.contact_shear_strength=25"}));
  REQUIRE(both.bonds.size() == 2 * pairs);
  CHECK(both.agglomerates[0].bonds == pairs);
  for (std::size_t k = 0; k < pairs; ++k) {
    CHECK(both.bonds[k].kind == rocklab::sim::BondKind::Parallel);
    CHECK(both.bonds[k].tensile_strength == 60e6);
    const auto& glue = both.bonds[pairs + k];
    CHECK(glue.kind == rocklab::sim::BondKind::Contact);
    CHECK(glue.a == both.bonds[k].a);
    CHECK(glue.b == both.bonds[k].b);
    CHECK(glue.tensile_strength == 40.0);
    CHECK(glue.shear_strength == 25.0);
  }
  // Weibull per agglomerate: one factor on every strength.
  const Scene drawn = loadScene(kZwick, small({"bonds.type=\"parallel+contact\"",
                                               "bonds.contact_normal_strength=40",
                                               "bonds.strength_distribution=\"weibull_per_agglomerate\"",
                                               "bonds.weibull_modulus=3"}));
  CHECK(drawn.bonds.back().tensile_strength / 40.0 ==
        Approx(drawn.bonds.front().tensile_strength / 60e6));

  CHECK_THAT(sceneError({"bonds.type=\"glue\""}),
             Catch::Contains("bonds.type") && Catch::Contains("parallel+contact"));
  CHECK_THAT(sceneError({"bonds.type=\"contact\"", "bonds.contact_normal_strength=40"}),
             Catch::Contains("bonds.radius_multiplier") && Catch::Contains("not with type = \"contact\""));
  CHECK_THAT(sceneError({"bonds.contact_normal_strength=40"}),
             Catch::Contains("bonds.contact_normal_strength") && Catch::Contains("not with type = \"parallel\""));
  CHECK_THAT(sceneError({"bonds.type=\"parallel+contact\""}), Catch::Contains("contact_normal_strength"));
  CHECK_THAT(sceneError({"bonds.type=\"parallel+contact\"", "bonds.contact_normal_strength=-3"}),
             Catch::Contains("contact_normal_strength"));
  // In a file: its name and line, the key, the value, what is allowed.
  const fs::path file =
      fs::temp_directory_path() / ("rocklab-contact-bonds-" + std::to_string(::getpid()) + ".toml");
  std::string text;
  {
    std::ifstream in(kZwick);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t at = text.find("[bonds]\n") + 8;
  text.insert(at, "type = \"glue\"\n");
  const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  std::ofstream(file) << text;
  std::string message = "accepted";
  try {
    loadScene(file.string());
  } catch (const SceneError& e) {
    message = e.what();
  }
  fs::remove(file);
  CHECK_THAT(message, Catch::Contains(file.filename().string() + ":" + std::to_string(line)) &&
                          Catch::Contains("key 'bonds.type' = \"glue\"") &&
                          Catch::Contains("allowed: \"parallel\", \"contact\", \"parallel+contact\""));
}

TEST_CASE("zwick: an agglomerate from a library brings its spheres and bonds into the scene",
          "[experiment][zwick]") {
  // A library of one agglomerate: a 20 mm HCP cluster (13 spheres) with its bonded pairs.
  AgglomerateRecord a;
  a.name = agglomerateGroupName(0);
  a.method = "hcp";
  a.r_max = 0.0025;
  a.diameter = 0.02;
  a.spheres = rocklab::geometry::hcpPacking(0.0025, 0.02, 0.0);
  for (const auto& [i, j] : rocklab::geometry::bondPairs(a.spheres, 1e-3))
    a.bonds.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j)});
  a.sphere_count = a.spheres.size();
  a.bond_count = a.bonds.size();
  const fs::path lib =
      fs::temp_directory_path() / ("rocklab-zwick-lib-" + std::to_string(::getpid()) + ".h5");
  writeAgglomerateLibrary(lib, {a});
  std::ifstream in(kZwick);
  std::stringstream text;
  text << in.rdbuf();
  std::string scene_text = text.str();
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = scene_text.find(from);
    REQUIRE(at != std::string::npos);
    scene_text.replace(at, from.size(), to);
  };
  replace("method = \"hcp\"",
          "method = \"library\"\nlibrary = \"" + lib.string() + "\"\nindex = 0");
  replace("radius = 0.0025 ", "# ");
  replace("diameter = 0.042 ", "# ");
  replace("hcp_angle = 0.0 ", "# ");
  const Scene scene = loadSceneText(scene_text, "library.toml");
  REQUIRE(scene.agglomerates.size() == 1);
  CHECK(scene.spheres.size() == a.spheres.size());
  REQUIRE(scene.bonds.size() == a.bonds.size());
  REQUIRE(a.bonds.size() > 3);
  CHECK(scene.bonds[3].a == a.bonds[3][0]);
  CHECK(scene.bonds[3].b == a.bonds[3][1]);
  CHECK(scene.agglomerates[0].method == "library:hcp");
  // An index past the end is refused with the library's size.
  scene_text.replace(scene_text.find("index = 0"), 9, "index = 4");
  try {
    loadSceneText(scene_text, "library.toml");
    FAIL("index 4 of a one-agglomerate library was accepted");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("holds 1 agglomerates"));
  }
  fs::remove(lib);
}
