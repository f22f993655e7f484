// Scene files: every class of bad input gives one message naming file, line,
// key, value and what is allowed; built-in scenes load.
#include <catch2/catch.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "drivers/chute_experiment.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/experiments/sweep.h"
#include "scene/scene_keys.h"
#include "scene/toml_reader.h"

using namespace rocklab::experiments;
using Catch::Contains;

namespace {
const std::string kMinimal = R"(
[scene]
name = "t"
end_time = 0.01

[materials.rock]
density = 2730
kn = 1e7

[[particles]]
type = "list"
material = "rock"
radius = 0.01
positions = [[0, 0, 0.1]]
)";

std::string errorOf(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    loadSceneText(text, "bad.toml", overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}
}  // namespace

TEST_CASE("a minimal scene loads with defaults", "[scene]") {
  const Scene s = loadSceneText(kMinimal, "min.toml");
  CHECK(s.spheres.size() == 1);
  CHECK(s.model.materials[0].ks == 1e7);  // ks defaults to kn
  CHECK(s.model.gravity.z() == -9.81);
  CHECK(s.run.end_time == 0.01);
}

TEST_CASE("unknown key: file - line and the known keys", "[scene]") {
  const std::string msg = errorOf(kMinimal + "\n[timestep]\nsaftey_factor = 0.3\n");
  CHECK_THAT(msg, Contains("bad.toml:17: unknown key 'timestep.saftey_factor'") &&
                      Contains("safety_factor"));
}

TEST_CASE("the renamed experiment.check_interval names its new key", "[scene]") {
  // Seconds under [experiment], steps under [watchdog]: the old name is refused with the new.
  CHECK_THAT(errorOf(kMinimal + "\n[experiment]\ntype = \"drop\"\ncheck_interval = 0.002\n"),
             Contains("bad.toml:18: key 'experiment.check_interval' = 0.002: renamed to "
                      "experiment.sample_interval (seconds)"));
  const Scene s = loadSceneText(
      kMinimal + "\n[experiment]\ntype = \"drop\"\nsample_interval = 0.004\n", "ok.toml");
  CHECK(s.experiment->sample_interval == 0.004);
}

TEST_CASE("wrong type: names the key - the value and the allowed values", "[scene]") {
  CHECK_THAT(errorOf(kMinimal + "\n[timestep]\nsafety_factor = \"fast\"\n"),
             Contains("bad.toml:17: key 'timestep.safety_factor' = \"fast\": expected a number") &&
                 Contains("(0, 1]"));
  CHECK_THAT(
      errorOf(kMinimal + "\n[contact]\nlaw = \"hooke\"\n"),
      Contains(
          "key 'contact.law' = \"hooke\": not allowed; allowed: \"linear\", \"hertz_mindlin\""));
}

TEST_CASE("out of range values are refused with the range", "[scene]") {
  CHECK_THAT(errorOf(kMinimal + "\n[contact]\ndamping_normal = 1.5\n"),
             Contains("key 'contact.damping_normal' = 1.5: out of range; allowed: [0, 1)"));
  CHECK_THAT(errorOf(kMinimal, {"materials.rock.density=-3"}),
             Contains("--set materials.rock.density=-3: key 'materials.rock.density' = -3: out of "
                      "range; allowed: > 0"));
}

TEST_CASE("missing pieces and files", "[scene]") {
  CHECK_THAT(errorOf("[scene]\nname = \"x\"\nend_time = 1\n"),
             Contains("key 'materials'") && Contains("missing"));
  CHECK_THAT(
      errorOf(kMinimal + "\n[[walls]]\ntype = \"plane\"\nmaterial = \"rock\"\nnormal = [0,0,1]\n"),
      Contains("key 'walls.0.point'") && Contains("missing"));
  CHECK_THAT(errorOf(kMinimal + "\n[[walls]]\ntype = \"mesh\"\nmaterial = \"steel\"\n"),
             Contains("key 'walls.0.material' = \"steel\": not allowed; allowed: \"rock\""));
  try {
    loadScene("/nonexistent/scene.toml");
    FAIL("no error");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("/nonexistent/scene.toml: cannot open the scene file"));
  }
  CHECK_THAT(errorOf("[scene\nname = 1"), Contains("bad.toml:1: TOML syntax error"));
}

TEST_CASE("option set overrides: values - array indices and bad paths", "[scene]") {
  const Scene s =
      loadSceneText(kMinimal, "t.toml",
                    {"particles.0.radius=0.02", "scene.end_time=2", "gravity.vector=[0,0,-1]"});
  CHECK(s.spheres[0].radius == 0.02);
  CHECK(s.run.end_time == 2.0);
  CHECK(s.model.gravity.z() == -1.0);
  CHECK_THAT(s.text, Contains("end_time = 2"));  // the effective scene is what gets stored
  CHECK_THAT(errorOf(kMinimal, {"particles.3.radius=1"}),
             Contains("index 3 is beyond the 1 entries"));
  CHECK_THAT(errorOf(kMinimal, {"noequals"}), Contains("expected key=value"));
  CHECK_THAT(errorOf(kMinimal, {"scene.end_tim=3"}),
             Contains("--set scene.end_tim=3: unknown key 'scene.end_tim'"));
}

TEST_CASE("option set overrides: one number of an array of numbers by its index", "[scene]") {
  // A sweep varies one component of a vector as a number (the zoned chute's CSS, walls.top.corner.2).
  const Scene s = loadSceneText(kMinimal + "\n[gravity]\nvector = [0.5, 0, -9.81]\n", "t.toml",
                                {"gravity.vector.2=-2", "gravity.vector.0=0.25", "particles.0.positions.0.2=0.3"});
  CHECK(s.model.gravity == Eigen::Vector3d(0.25, 0, -2));
  CHECK(s.spheres[0].position.z() == 0.3);
  // The reader still checks the array as a whole, and the message names the --set.
  CHECK_THAT(errorOf(kMinimal, {"particles.0.positions.0.2=\"x\""}),
             Contains("--set particles.0.positions.0.2=\"x\": entry 2 of 'particles.0.positions.0' is a number and the "
                      "value a string"));
  CHECK_THAT(errorOf(kMinimal, {"particles.0.positions.0.3=1"}),
             Contains("'particles.0.positions.0' is an array of 3; '3' must be an index into it (allowed: 0 to 2"));
  CHECK_THAT(errorOf(kMinimal, {"particles.0.positions.x=1"}), Contains("'x' must be an index into it"));
  // An array of arrays: its entries are set whole, not by a number.
  CHECK_THAT(errorOf(kMinimal, {"particles.0.positions.0=1"}),
             Contains("entry 0 of 'particles.0.positions' is an array and the value an integer"));
}

// Loading checks keys and values; the first steps check what only the world
// sees: a ball generated into a wall the scene keeps (zoned-chute-single kept
// the zoned chute's zone walls it had not generated around, and stopped at
// step 0 under the watchdog).
TEST_CASE("every built-in scene loads and takes its first steps", "[scene]") {
  int count = 0;
  const auto out = std::filesystem::temp_directory_path() / "rocklab-scene-first-steps";
  for (const auto& e : std::filesystem::directory_iterator(builtinSceneDir())) {
    if (e.path().extension() != ".toml") continue;
    INFO(e.path());
    Scene scene;
    REQUIRE_NOTHROW(scene = loadScene(e.path()));
    scene.run.end_time = 0.0;
    scene.run.steps = 3;
    RunOptions options;
    options.out_dir = out / e.path().stem();
    options.threads = 1;
    options.progress = false;
    std::ostringstream log;
    const int code = runScene(scene, options, log);
    INFO(log.str());
    CHECK(code == kExitOk);
    ++count;
  }
  CHECK(count >= 1);
  std::filesystem::remove_all(out);
}

TEST_CASE("mesh walls from an STL file (assimp) and inline triangles", "[scene]") {
  const auto dir = std::filesystem::temp_directory_path() / "rocklab-scene-mesh";
  std::filesystem::create_directories(dir);
  {
    std::ofstream stl(dir / "floor.stl");
    stl << "solid floor\n"
           " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1000 0 0\n   vertex 1000 "
           "1000 0\n"
           "  endloop\n endfacet\n"
           " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1000 1000 0\n   vertex 0 "
           "1000 0\n"
           "  endloop\n endfacet\nendsolid floor\n";
  }
  const std::string walls = R"(
[[walls]]
type = "mesh"
material = "rock"
file = "floor.stl"
scale = 0.001          # the file is in mm

[[walls]]
type = "mesh"
material = "rock"
vertices = [[0, 0, 1], [1, 0, 1], [0, 1, 1]]
triangles = [[0, 1, 2]]
)";
  const Scene s = loadSceneText(kMinimal + walls, "mesh.toml", {}, dir);
  REQUIRE(s.model.walls.size() == 2);
  CHECK(s.model.walls[0].mesh.triangleCount() == 2);
  CHECK(s.model.walls[0].mesh.vertices.size() == 4);  // welded
  CHECK(s.model.walls[0].mesh.bounds().hi.x() == Approx(1.0));
  CHECK(s.model.walls[1].mesh.triangleCount() == 1);
  // `offset` moves a mesh after its scale: the file's floor (mm) 0.25 m up and 1 m along x.
  const Scene moved = loadSceneText(kMinimal + walls, "mesh.toml", {"walls.0.offset=[1.0, 0, 0.25]"}, dir);
  CHECK(moved.model.walls[0].mesh.bounds().lo.x() == Approx(1.0));
  CHECK(moved.model.walls[0].mesh.bounds().hi.x() == Approx(2.0));
  CHECK(moved.model.walls[0].mesh.bounds().lo.z() == Approx(0.25));
  CHECK(moved.model.walls[1].mesh.bounds().lo.z() == Approx(1.0));  // the other mesh stays
  CHECK_THAT(errorOf(kMinimal + "\n[[walls]]\ntype = \"mesh\"\nmaterial = \"rock\"\nvertices = [[0, 0, 1], [1, 0, 1], "
                                "[0, 1, 1]]\ntriangles = [[0, 1, 2]]\noffset = [1, 2]\n"),
             Contains("key 'walls.0.offset' = [1, 2]: expected an array of 3 finite numbers"));
  CHECK_THAT(errorOf(kMinimal +
                     "\n[[walls]]\ntype = \"mesh\"\nmaterial = \"rock\"\nfile = \"missing.stl\"\n"),
             Contains("key 'walls.0.file' = \"missing.stl\": cannot read mesh"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("a scene extends another and changes only what it names", "[scene]") {
  const std::string dir = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/";
  const Scene base = loadScene(dir + "chute-30-clumps.toml");
  const Scene steep = loadScene(dir + "chute-33-clumps.toml");
  CHECK(settingsOf<ChuteSettings>(steep).inclination_deg == 33.0);
  CHECK(steep.run.name == "chute-33-clumps");
  CHECK(steep.clumps.size() == base.clumps.size());
  CHECK(steep.model.walls.size() == base.model.walls.size());
  CHECK(settingsOf<ChuteSettings>(steep).marker_columns ==
        settingsOf<ChuteSettings>(base).marker_columns);
  const Scene spheres = loadScene(dir + "chute-30-spheres.toml");  // [[particles]] replaced whole
  CHECK(spheres.clumps.empty());
  CHECK(spheres.spheres.size() == 1680);
  CHECK_THROWS_WITH(loadSceneText("extends = \"nowhere.toml\"\n", "x.toml", {}, dir),
                    Contains("x.toml:1: key 'extends' = \"nowhere.toml\": cannot open"));
}

TEST_CASE("an extending scene removes inherited entries by name, and a name that matches nothing is refused",
          "[scene]") {
  const std::string dir = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/";
  const Scene zoned = loadScene(dir + "zoned-chute.toml");
  const Scene single = loadScene(dir + "zoned-chute-single.toml");
  auto names = [](const Scene& s) {
    std::vector<std::string> n;
    for (const auto& w : s.model.walls) n.push_back(w.name);
    return n;
  };
  std::vector<std::string> kept = names(zoned);
  std::erase_if(kept, [](const std::string& n) { return n == "zone_wall_1" || n == "zone_wall_2"; });
  REQUIRE(kept.size() + 2 == zoned.model.walls.size());
  CHECK(names(single) == kept);  // the rest in their order
  const std::string extend = "extends = \"zoned-chute.toml\"\n";
  CHECK_THROWS_WITH(loadSceneText(extend + "remove = [\"walls.zone_wall_3\"]\n", "x.toml", {}, dir),
                    Contains("x.toml:2: key 'remove' entry \"walls.zone_wall_3\": no [[walls]] entry is named "
                             "'zone_wall_3'") &&
                        Contains("zone_wall_1, zone_wall_2"));
  CHECK_THROWS_WITH(loadSceneText(extend + "remove = [\"floors.base\"]\n", "x.toml", {}, dir),
                    Contains("the scene has no array of tables [[floors]]"));
  CHECK_THROWS_WITH(loadSceneText(extend + "remove = [\"walls\"]\n", "x.toml", {}, dir),
                    Contains("expected ARRAY.NAME"));
  CHECK_THROWS_WITH(loadSceneText(extend + "remove = \"walls.gate\"\n", "x.toml", {}, dir),
                    Contains("key 'remove': expected a list"));
  // Removing an entry twice: the second finds nothing.
  CHECK_THROWS_WITH(loadSceneText(extend + "remove = [\"walls.gate\", \"walls.gate\"]\n", "x.toml", {}, dir),
                    Contains("no [[walls]] entry is named 'gate'"));
}

TEST_CASE("messages name the --set or file - line of the key they blame - with short numbers", "[scene]") {
  // A table only a --set made: the override, not "<scene>".
  const std::string made = errorOf(kMinimal, {"foo.bar=1"});
  CHECK_THAT(made, Contains("--set foo.bar=1: unknown key 'foo'"));
  CHECK_THAT(made, !Contains("<scene>"));
  // An empty key part would replace a table: refused, as is a value for a table.
  CHECK_THAT(errorOf(kMinimal, {"scene.=1"}), Contains("--set scene.=1: the key has an empty part"));
  CHECK_THAT(errorOf(kMinimal, {".scene=1"}), Contains("empty part"));
  CHECK_THAT(errorOf(kMinimal, {"scene=1"}), Contains("--set scene=1: 'scene' is a table"));
  CHECK_THAT(errorOf(kMinimal, {"particles.0=1"}), Contains("'particles' is an array of tables"));
  CHECK_THAT(errorOf(kMinimal, {"particles.0.radius.x=1"}), Contains("'particles.0.radius' is a number, not a table"));
  // Numbers as written, not 17 digits (toml++ prints -0.0040000000000000001).
  const std::string negative = errorOf(kMinimal, {"scene.end_time=-0.004"});
  CHECK_THAT(negative, Contains("--set scene.end_time=-0.004: key 'scene.end_time' = -0.004: out of range"));
  CHECK_THAT(errorOf(kMinimal + "\n[gravity]\nvector = [0.1, 0.2]\n"), Contains("= [0.1, 0.2]"));
  // What the World would refuse without a key: the reader says key and line.
  std::string stiffless = kMinimal;
  stiffless.replace(stiffless.find("kn = 1e7"), 8, "kn = 0");
  CHECK_THAT(errorOf(stiffless), Contains("bad.toml:8: key 'materials.rock.kn' = 0: the linear contact law"));
  CHECK_THAT(errorOf(kMinimal, {"materials.rock.kn=0"}), Contains("--set materials.rock.kn=0: key 'materials.rock.kn'"));
  CHECK_THAT(errorOf(kMinimal, {"contact.law=\"hertz_mindlin\""}),
             Contains("bad.toml:6: key 'materials.rock.shear_modulus'"));
  const std::string polygon = "\n[[walls]]\ntype = \"polygon\"\nmaterial = \"rock\"\n"
                              "vertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\n";
  CHECK_THAT(errorOf(kMinimal + polygon), Contains("bad.toml:19: key 'walls.0.vertices'") && Contains("collinear"));
  const std::string skew = "\n[[walls]]\ntype = \"polygon\"\nmaterial = \"rock\"\n"
                           "vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.5]]\n";
  CHECK_THAT(errorOf(kMinimal + skew), Contains("vertex 3 is not in the plane"));
  // A folder is not a scene; `extends` says its line.
  const auto dir = std::filesystem::temp_directory_path();
  CHECK_THROWS_WITH(loadScene(dir), Contains("is a directory"));
  CHECK_THAT(errorOf(kMinimal + "\n[[walls]]\ntype = \"mesh\"\nmaterial = \"rock\"\nfile = \"" + dir.string() + "\"\n"),
             Contains("key 'walls.0.file'") && Contains("is a directory"));
  CHECK_THAT(errorOf("extends = \".\"\n"), Contains("bad.toml:1: key 'extends'") && Contains("is a directory"));
}

TEST_CASE("set overrides address an array entry by its name", "[scene]") {
  const std::string file = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/zoned-chute.toml";
  const Scene s = loadScene(file, {"walls.top.angle_deg=30", "walls.top.corner=[0, 0, 0.04]"});
  const auto& top = s.model.walls.back();
  REQUIRE(top.name == "top");
  CHECK(top.vertices[0].z() == Approx(0.04));
  CHECK(top.vertices[1].z() == Approx(0.04 + 0.65 * 0.5));
  CHECK_THROWS_WITH(
      loadScene(file, {"walls.nosuchwall.angle_deg=3"}),
      Contains("'nosuchwall' must be an index into the array or the name of one of its entries"));
}

TEST_CASE("vary values keep commas inside brackets", "[scene]") {
  const auto [key, values] = parseVary("walls.top.corner=[0,0,0.03],[0,0,0.05]");
  CHECK(key == "walls.top.corner");
  CHECK(values == std::vector<std::string>{"[0,0,0.03]", "[0,0,0.05]"});
  CHECK(parseVary("a=1,2,3").second.size() == 3);
  CHECK_THROWS(parseVary("novalues="));
}

TEST_CASE("clump sources: four-ball by equivalent diameter and a clump file", "[scene]") {
  const std::string text = R"(
[scene]
name = "clumps"
end_time = 0.1
[materials.rock]
density = 2000.0
[[particles]]
type = "list"
shape = "four_ball"
equivalent_diameter = 0.02
material = "rock"
positions = [[0.0, 0.0, 0.1]]
[[particles]]
type = "random"
shape = "file"
file = "../clumps/three-ball.txt"
mass_distribution = "equal_mass"
material = "rock"
count = 5
region_min = [0.1, 0.1, 0.1]
region_max = [0.2, 0.2, 0.2]
)";
  const Scene s =
      loadSceneText(text, "clumps.toml", {}, std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes");
  REQUIRE(s.clumps.size() == 6);
  REQUIRE(s.clump_shapes.size() == 2);
  // Eq 4-2 sizing: the clump's mass is that of a 20 mm sphere of the density.
  CHECK(s.clumps[0].mass == Approx(2000.0 * M_PI / 6.0 * 8e-6).epsilon(1e-9));
  CHECK(s.clump_shapes[0].equivalent_diameter == Approx(0.02).epsilon(1e-9));
  CHECK(s.clumps[1].members.size() == 3);
  CHECK(s.clump_shapes[1].distribution == "equal_mass");
  // Members are given about the centre of mass: their mean is the origin for equal masses.
  rocklab::geometry::Vec3 mean = rocklab::geometry::Vec3::Zero();
  for (const auto& m : s.clumps[1].members) mean += m.centre / 3.0;
  CHECK(mean.norm() < 1e-12);
  CHECK_THROWS_WITH(loadSceneText(text, "clumps.toml", {"particles.1.file=\"nope.txt\""},
                                  std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes"),
                    Contains("particles.1.file"));
}

TEST_CASE("a random source takes its sphere sizes from a product file", "[scene]") {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "rocklab-diameters";
  std::filesystem::create_directories(dir);
  {
    std::ofstream product(dir / "product.csv");
    product << "id,time_s,diameter_mm,mass_kg,residence_s\n1,0.5,12,0.002,0.4\n2,0.6,8.5,0.001,0.3\n3,0.7,20,0.01,nan\n";
    std::ofstream bad(dir / "bad.csv");
    bad << "id,diameter_mm\n1,12\n2,-3\n";
    std::ofstream none(dir / "none.csv");
    none << "id,size\n1,12\n";
  }
  const std::string text = R"(
[scene]
name = "from-product"
end_time = 0.1
[materials.rock]
density = 2730.0
[[particles]]
type = "random"
material = "rock"
diameters_file = "product.csv"
region_min = [0.0, 0.0, 0.0]
region_max = [0.2, 0.2, 0.1]
)";
  const Scene s = loadSceneText(text, "product.toml", {}, dir.string());
  REQUIRE(s.spheres.size() == 3);
  std::vector<double> radii;
  for (const auto& b : s.spheres) radii.push_back(b.radius);
  std::sort(radii.begin(), radii.end());
  CHECK(radii[0] == Approx(0.00425));
  CHECK(radii[1] == Approx(0.006));
  CHECK(radii[2] == Approx(0.010));
  // A bad row names the file, the line and the value; a count beside the file is refused.
  CHECK_THROWS_WITH(loadSceneText(text, "product.toml", {"particles.0.diameters_file=\"bad.csv\""}, dir.string()),
                    Contains("bad.csv line 3") && Contains("'-3'"));
  CHECK_THROWS_WITH(loadSceneText(text, "product.toml", {"particles.0.diameters_file=\"none.csv\""}, dir.string()),
                    Contains("no diameter_mm or diameter_m column"));
  CHECK_THROWS_WITH(loadSceneText(text, "product.toml", {"particles.0.count=5"}, dir.string()),
                    Contains("diameters_file gives the spheres"));
}

TEST_CASE("camera keys are checked and a scene without cameras has none", "[scene]") {
  const std::string file = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/chute-30-clumps.toml";
  const Scene s = loadScene(file);
  REQUIRE(s.cameras.size() == 1);
  CHECK(s.cameras[0].camera.frameRate == 500.0);
  CHECK(s.cameras[0].camera.width == 960);
  CHECK(s.wall_looks.size() == s.model.walls.size());
  CHECK(s.wall_looks[1].opacity == Approx(0.15));  // the camera-side Perspex
  CHECK(loadScene(std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/drop.toml").cameras.empty());
  // A named camera is named in messages as --set addresses it.
  CHECK_THROWS_WITH(loadScene(file, {"cameras.side.resolution=[960]"}),
                    Contains("cameras.side.resolution"));
  CHECK_THROWS_WITH(loadScene(file, {"cameras.side.fov_deg=200"}), Contains("cameras.side.fov_deg"));
  // The eye on the target is the eye's fault, not up's.
  CHECK_THROWS_WITH(loadScene(file, {"cameras.side.eye=[0.27, 0.15, 0.05]"}),
                    Contains("key 'cameras.side.eye'") && Contains("equals target"));
  CHECK_THROWS_WITH(loadScene(file, {"cameras.side.up=[0, 1, 0]"}), Contains("key 'cameras.side.up'"));
  CHECK_THROWS_WITH(loadScene(file, {"cameras.side.motion_blur=true"}),
                    Contains("needs exposure > 0 s"));
  CHECK_THROWS_WITH(loadScene(file, {"cameras.side.lens=1"}), Contains("cameras.side.lens"));
  CHECK_THROWS_WITH(loadScene(file, {"cameras.side.k1=-3"}), Contains("key 'cameras.side.k1'"));
}

TEST_CASE(
    "contact.stiffness_scale scales every material's stiffness - and spaces around = in --set",
    "[scene]") {
  const Scene s = loadSceneText(kMinimal, "min.toml", {"contact.stiffness_scale = 0.01"});
  CHECK(s.model.materials[0].kn == Approx(1e5));
  CHECK(s.model.materials[0].ks == Approx(1e5));
  CHECK_THAT(errorOf(kMinimal, {"contact.stiffness_scale=0"}),
             Contains("stiffness_scale") && Contains("> 0"));
}

TEST_CASE("watchdog network keys and relaxation.steps are read and range-checked", "[scene]") {
  const Scene s = loadSceneText(
      kMinimal, "t.toml",
      {"relaxation.steps=5000", "watchdog.network_iterations=0", "watchdog.network_interval=250"});
  CHECK(s.model.relaxation.steps == 5000);
  CHECK(s.model.watchdog.network_iterations == 0);
  CHECK(s.model.watchdog.network_interval == 250);
  const Scene d = loadSceneText(kMinimal, "t.toml", {});
  CHECK(d.model.relaxation.steps == 0);  // off unless asked
  CHECK(d.model.watchdog.network_iterations > 0);
  CHECK_THAT(errorOf(kMinimal, {"relaxation.steps=-1"}), Contains("relaxation.steps"));
  CHECK_THAT(errorOf(kMinimal, {"watchdog.network_interval=0"}), Contains("network_interval"));
}

TEST_CASE("the readers record every key they read, for the scene reference", "[scene]") {
  using rocklab::experiments::detail::KeyRead;
  namespace d = rocklab::experiments::detail;
  d::recordSceneKeys(true);
  loadSceneText(kMinimal + "\n[[walls]]\ntype = \"plane\"\nmaterial = \"rock\"\npoint = [0, 0, 0]\n"
                           "normal = [0, 0, 1]\n[walls.motion]\nvelocity = [0, 0, 1]\n",
                "keys.toml");
  const std::vector<KeyRead> reads = d::recordedSceneKeys();
  d::recordSceneKeys(false);
  auto find = [&](const std::string& table, const std::string& key) -> const KeyRead* {
    for (const KeyRead& r : reads)
      if (r.table == table && r.key == key && !r.kind.empty()) return &r;
    return nullptr;
  };
  // A named entry's table is documented as NAME; its defaults are the reader's own.
  const KeyRead* density = find("materials.NAME", "density");
  REQUIRE(density);
  CHECK(density->kind == "number");
  CHECK(density->allowed == "> 0");
  CHECK(density->fallback == "2730");
  CHECK_FALSE(density->required);
  // Array entries drop their index; required keys have no default.
  const KeyRead* name = find("scene", "name");
  REQUIRE(name);
  CHECK(name->required);
  const KeyRead* law = find("contact", "law");
  CHECK_FALSE(law);  // no [contact] table in the scene: its keys are not read
  const KeyRead* point = find("walls", "point");
  REQUIRE(point);
  CHECK(point->kind == "[x, y, z]");
  REQUIRE(find("walls.motion", "velocity"));
  REQUIRE(find("particles", "positions"));
  // Nothing is recorded while recording is off.
  loadSceneText(kMinimal, "again.toml");
  CHECK(d::recordedSceneKeys().size() == reads.size());
}

TEST_CASE("every documented scene key names its table and says what it does", "[scene]") {
  for (const KeyDoc& k : sceneKeyDocs()) {
    INFO(std::string(k.table) + " " + k.key);
    CHECK(std::string(k.text).size() > 5);
    CHECK(std::string(k.text).find('|') == std::string::npos);  // a Markdown table cell
  }
}

TEST_CASE("a --set key path's unit, for axis labels, from the scene reference", "[scene]") {
  CHECK(sceneKeyUnit("walls.top.corner.2") == "m");  // the zoned chute's CSS
  CHECK(sceneKeyUnit("walls.top.angle_deg") == "deg");
  CHECK(sceneKeyUnit("particles.0.member_radius") == "m");
  CHECK(sceneKeyUnit("experiment.inclination_deg") == "deg");
  CHECK(sceneKeyUnit("experiment.breakage.q_ref") == "Pa");
  CHECK(sceneKeyUnit("scene.seed").empty());       // a number without a unit
  CHECK(sceneKeyUnit("walls.top.no_such_key").empty());
  CHECK(sceneKeyUnit("seed").empty());
  CHECK(withSceneKeyUnit("walls.top.corner.2") == "walls.top.corner.2 (m)");
  CHECK(withSceneKeyUnit("scene.seed") == "scene.seed");
}
