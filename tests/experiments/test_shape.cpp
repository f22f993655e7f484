// `rocklab shape` in-process: outputs, the clump in a scene, bad input, real scans.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_support.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/experiments/shape.h"
#include "rocklab/geometry/clump_shape.h"
#include "rocklab/geometry/mesh_check.h"
#include "rocklab/geometry/mesh_generate.h"
#include "rocklab/geometry/mesh_properties.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {
using rocklab::experiments::test::cli;
fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rocklab-shape-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
json readJson(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}
}  // namespace

TEST_CASE("rocklab shape turns a generated pebble into a clump with its errors", "[shape]") {
  const fs::path dir = tempDir("pebble");
  const fs::path out = dir / "out";
  // A pebble written in millimetres, 20 mm equivalent diameter.
  REQUIRE(cli({"shape", (dir / "pebble.stl").string(), "--generate", "pebble", "--seed", "3", "--unit", "mm", "--size",
               "0.02", "--spheres", "12", "--out", out.string()}) == 0);
  for (const char* f : {"clump.txt", "clump.toml", "preview.png", "results.json"}) CHECK(fs::exists(out / f));
  const json r = readJson(out / "results.json");
  CHECK(r["sphere_count"] == 12);
  CHECK(r["mesh"]["equivalent_diameter_m"].get<double>() == Approx(0.02).epsilon(1e-6));
  // Inscribed spheres: the clump is smaller than the pebble, by less than half.
  CHECK(r["volume_error"].get<double>() < 0);
  CHECK(r["volume_error"].get<double>() > -0.5);
  CHECK(r["inertia_error"].get<double>() > 0);
  CHECK(r["surface_error_max_m"].get<double>() >= r["surface_error_mean_m"].get<double>());
  CHECK(r["surface_error_mean_m"].get<double>() < 0.002);
  CHECK(r["checks"]["warnings"].empty());
  CHECK(r["wall_time_s"].get<double>() > 0);
  const auto members = rocklab::geometry::readClumpFile((out / "clump.txt").string());
  CHECK(members.size() == 12);

  // The clump in a scene carries the mesh's mass and principal moments (clump.toml).
  std::ifstream keys(out / "clump.toml");
  std::stringstream text;
  text << "[scene]\nname = \"t\"\nend_time = 0.001\n[materials.rock]\ndensity = 2730\nkn = 1e7\nks = 1e7\n"
          "friction = 0.3\n[[particles]]\ntype = \"list\"\nmaterial = \"rock\"\npositions = [[0.0, 0.0, 0.1]]\n"
       << keys.rdbuf();
  const auto scene = rocklab::experiments::loadSceneText(text.str(), "pile.toml", {}, out);
  REQUIRE(scene.clumps.size() == 1);
  CHECK(scene.clumps[0].mass == Approx(r["mesh"]["mass_kg"].get<double>()).epsilon(1e-6));
  for (int a = 0; a < 3; ++a)
    CHECK(scene.clumps[0].principal_inertia[a] ==
          Approx(r["mesh"]["principal_moments_kg_m2"][a].get<double>()).epsilon(1e-6));
}

TEST_CASE("rocklab shape sweep tabulates both methods and times a small pile", "[shape]") {
  const fs::path dir = tempDir("sweep");
  const fs::path out = dir / "out";
  REQUIRE(cli({"shape", (dir / "rock.ply").string(), "--generate", "crushed", "--size", "0.02", "--sweep", "1,4,8",
               "--pile", "--pile-clumps", "8", "--pile-time", "0.002", "--no-preview", "--out", out.string()}) == 0);
  const json r = readJson(out / "results.json");
  REQUIRE(r["sweep"].size() == 6);
  int timed = 0;
  for (const auto& row : r["sweep"]) timed += row.contains("pile_clump_steps_per_s");
  CHECK(timed == 3);  // the chosen method's counts
  CHECK(fs::exists(out / "shape_sweep.csv"));
  CHECK(fs::exists(out / "shape_sweep.png"));
  CHECK(fs::exists(out / "shape_cost.png"));
  CHECK_FALSE(fs::exists(out / "preview.png"));
}

TEST_CASE("rocklab shape refuses bad input with exit code 2 and writes nothing", "[shape]") {
  const fs::path dir = tempDir("bad");
  const fs::path out = dir / "out";
  CHECK(cli({"shape", (dir / "missing.stl").string(), "--out", out.string()}) == 2);
  CHECK(cli({"shape", (dir / "x.stl").string(), "--generate", "pebble", "--method", "voxel", "--out", out.string()}) == 2);
  CHECK(cli({"shape", (dir / "x.stl").string(), "--generate", "pebble", "--unit", "inch", "--out", out.string()}) == 2);
  CHECK(cli({"shape", (dir / "x.stl").string(), "--generate", "boulder", "--out", out.string()}) == 2);
  // An open mesh (a box without one triangle).
  auto box = rocklab::geometry::boxMesh({0, 0, 0}, {0.01, 0.01, 0.01});
  box.triangles.pop_back();
  rocklab::geometry::writeMeshFile((dir / "open.obj").string(), box);
  CHECK(cli({"shape", (dir / "open.obj").string(), "--out", out.string()}) == 2);
  CHECK_FALSE(fs::exists(out));
}

TEST_CASE("rocklab shape warns about a size implausible for the stated unit", "[shape]") {
  const fs::path dir = tempDir("unit");
  // Generated at 20 mm in millimetres, then read as metres: a 20 m stone.
  REQUIRE(cli({"shape", (dir / "p.obj").string(), "--generate", "pebble", "--unit", "mm", "--size", "0.02", "--spheres",
               "2", "--no-preview", "--out", (dir / "a").string()}) == 0);
  REQUIRE(cli({"shape", (dir / "p.obj").string(), "--unit", "m", "--spheres", "2", "--no-preview", "--out",
               (dir / "b").string()}) == 0);
  const json r = readJson(dir / "b" / "results.json");
  REQUIRE(r["checks"]["warnings"].size() == 1);
  CHECK_THAT(r["checks"]["warnings"][0].get<std::string>(), Catch::Contains("implausible size for --unit m"));
  CHECK(readJson(dir / "a" / "results.json")["checks"]["warnings"].empty());
}

// Real scans (GPL-3.0, not part of the project; docs/shape.md lists the five
// measured): the folder named by ROCKLAB_SCAN_DIR (any folder of closed STL/PLY/OBJ
// scans). Skipped without it.
TEST_CASE("rocklab shape on real scans (ROCKLAB_SCAN_DIR)", "[shape][validation]") {
  const char* env = std::getenv("ROCKLAB_SCAN_DIR");
  if (!env || !*env) {
    WARN("ROCKLAB_SCAN_DIR not set: skipped");
    return;
  }
  const fs::path scans(env);
  if (!fs::exists(scans)) {
    WARN("ROCKLAB_SCAN_DIR=" << scans.string() << " does not exist: skipped");
    return;
  }
  const fs::path dir = tempDir("scans");
  for (const auto& e : fs::directory_iterator(scans)) {
    const std::string ext = e.path().extension().string();
    if (ext != ".stl" && ext != ".obj") continue;
    const fs::path out = dir / e.path().stem();
    INFO(e.path().string());
    REQUIRE(cli({"shape", e.path().string(), "--spheres", "32", "--no-preview", "--out", out.string()}) == 0);
    const json r = readJson(out / "results.json");
    CHECK(r["volume_error"].get<double>() < 0.01);
    CHECK(r["volume_error"].get<double>() > -0.6);
    CHECK(r["checks"]["shells"] == 1);
  }
}

TEST_CASE("rocklab shape works on every mesh in assets/meshes", "[shape]") {
  const fs::path assets = fs::path(ROCKLAB_SOURCE_DIR) / "assets" / "meshes";
  const fs::path dir = tempDir("assets");
  int meshes = 0;
  for (const auto& e : fs::directory_iterator(assets)) {
    const std::string ext = e.path().extension().string();
    if (ext != ".stl" && ext != ".ply" && ext != ".obj") continue;
    ++meshes;
    INFO(e.path().string());
    const fs::path out = dir / e.path().filename();
    REQUIRE(cli({"shape", e.path().string(), "--unit", "mm", "--spheres", "8", "--no-preview", "--out", out.string()}) == 0);
    const json r = readJson(out / "results.json");
    CHECK(r["checks"]["warnings"].empty());  // generated meshes are clean
    CHECK(r["mesh"]["equivalent_diameter_m"].get<double>() == Approx(0.02).epsilon(0.001));
    CHECK(r["volume_error"].get<double>() <= 0.0);  // inscribed spheres
    // 8 inscribed spheres measured -9.1 to -21.8 % on the pebbles and the crushed
    // rock and -57.7 % on the flake (deterministic): each held to about 5 points
    // below its class's worst, so a lost sphere (a -30 % step at 8) fails.
    const bool flake = e.path().filename().string().starts_with("flake");
    CHECK(r["volume_error"].get<double>() > (flake ? -0.63 : -0.27));
  }
  CHECK(meshes >= 3);
}

TEST_CASE("the mesh-clump chute scene loads with the meshes' mass and inertia", "[shape]") {
  const auto scene = rocklab::experiments::loadScene(fs::path(ROCKLAB_SOURCE_DIR) / "assets" / "scenes" /
                                                     "chute-30-mesh-clumps.toml");
  REQUIRE(scene.clumps.size() == 1680);
  REQUIRE(scene.clump_shapes.size() == 3);
  // From each STL: the mesh taken to the scene's size, 19.9 mm equivalent diameter
  // (the Eq 4-2 size of the four-ball clumps, scripts/make-shape-assets.sh), at the
  // pebble density 2730 kg/m^3: mass rho pi d^3 / 6, principal moments those of
  // the mesh in mm scaled by s^5 (s = 19.9 mm / its equivalent diameter).
  // 1e-6: the scene file states them to 9 digits, the STL's floats to 7.
  const double rho = 2730, d = 0.0199, mass = rho * std::numbers::pi * d * d * d / 6;
  std::vector<rocklab::geometry::Vec3> moments;
  for (int k = 1; k <= 3; ++k) {
    const auto mesh = rocklab::geometry::readMeshFile(
        (fs::path(ROCKLAB_SOURCE_DIR) / "assets" / "meshes" / ("pebble-" + std::to_string(k) + ".stl")).string(), 1e-3);
    const auto props = rocklab::geometry::meshMassProperties(mesh, rho);
    const double s = d / std::cbrt(6 * props.volume / std::numbers::pi);
    CHECK(s == Approx(1.0).margin(0.01));  // the meshes are 20 mm ones
    moments.push_back(props.principal_moments * std::pow(s, 5));
    INFO("pebble-" << k);
    CHECK(scene.clump_shapes[k - 1].mass == Approx(mass).epsilon(1e-6));
    for (int a = 0; a < 3; ++a)
      CHECK(scene.clump_shapes[k - 1].principal_inertia[a] == Approx(moments.back()[a]).epsilon(1e-6));
  }
  // Every clump carries its own shape's mass and moments, 560 of each.
  int of_shape[3] = {0, 0, 0};
  for (const auto& c : scene.clumps) {
    CHECK(c.members.size() == 16);
    CHECK(c.mass == Approx(mass).epsilon(1e-6));
    for (int k = 0; k < 3; ++k) of_shape[k] += (c.principal_inertia - moments[k]).norm() < 1e-6 * moments[k].norm();
  }
  CHECK(of_shape[0] == 560);
  CHECK(of_shape[1] == 560);
  CHECK(of_shape[2] == 560);
}

TEST_CASE("the clump frame is the mesh's principal frame and a scene keeps it", "[shape]") {
  // clump.txt is written about the mesh's centroid and principal axes, with the transform
  // back to the file; a scene with principal_inertia keeps the members in that frame (the
  // union's own axes turn by up to tens of degrees for a flake, whose two larger moments
  // are close, and would put the mesh's moments on the wrong axes).
  const fs::path dir = tempDir("axes");
  for (const char* kind : {"pebble", "crushed", "flake"}) {
    INFO(kind);
    const fs::path out = dir / kind, mesh_file = dir / (std::string(kind) + ".stl");
    REQUIRE(cli({"shape", mesh_file.string(), "--generate", kind, "--unit", "mm", "--size", "0.02", "--spheres", "16",
                 "--no-preview", "--out", out.string()}) == 0);
    const json r = readJson(out / "results.json");
    // The mesh taken into the clump frame by the stated transform: x = Rᵀ (s x_file − t).
    const auto& tf = r["clump"]["to_file_frame"];
    rocklab::geometry::Mat3 R;
    rocklab::geometry::Vec3 t;
    for (int i = 0; i < 3; ++i) {
      t[i] = tf["t_m"][i].get<double>();
      for (int j = 0; j < 3; ++j) R(i, j) = tf["R"][i][j].get<double>();
    }
    auto mesh = rocklab::geometry::readMeshFile(mesh_file.string(), 1.0);
    for (auto& v : mesh.vertices) v = R.transpose() * (tf["s_m_per_file_unit"].get<double>() * v - t);
    const auto props = rocklab::geometry::meshMassProperties(mesh, 2730);
    CHECK(props.centroid.norm() < 1e-7);
    for (int a = 0; a < 3; ++a) {
      CHECK(props.inertia(a, a) == Approx(r["mesh"]["principal_moments_kg_m2"][a].get<double>()).epsilon(1e-5));
      CHECK(std::abs(props.inertia(a, (a + 1) % 3)) < 1e-6 * props.inertia.norm());
    }
    // A scene with the clump.toml keys keeps the file's members and moments as they are.
    std::ifstream keys(out / "clump.toml");
    std::stringstream text;
    text << "[scene]\nname = \"t\"\nend_time = 0.001\n[materials.rock]\ndensity = 2730\nkn = 1e7\nks = 1e7\n"
            "friction = 0.3\n[[particles]]\ntype = \"list\"\nmaterial = \"rock\"\npositions = [[0.0, 0.0, 0.1]]\n"
         << keys.rdbuf();
    const auto scene = rocklab::experiments::loadSceneText(text.str(), "t.toml", {}, out);
    const auto members = rocklab::geometry::readClumpFile((out / "clump.txt").string());
    REQUIRE(scene.clumps.at(0).members.size() == members.size());
    for (std::size_t k = 0; k < members.size(); ++k)
      CHECK((scene.clumps[0].members[k].centre - members[k].centre).norm() < 1e-12);
  }
}
