// The cone crusher's scene table ([crusher]) and `rocklab crusher-geometry`.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "rocklab/experiments/scene.h"

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
    CHECK(w.motion.isStatic());  // the engine cannot move the mantle yet (docs/crusher.md)
    CHECK(w.mesh.validate().empty());
  }
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
