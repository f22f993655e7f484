// The crush movie (issue 20): balls coloured by fragment from the bond state,
// live (FrameBuilder) and re-rendered from run.h5 (rocklab render), platens
// drawn as discs; the scene keys that ask for it.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <tuple>

#include "camera/fragment_colours.h"
#include "camera/frame_builder.h"
#include "camera/render_run.h"
#include "camera/wall_placement.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/sim/output/run_file.h"

namespace fs = std::filesystem;
using namespace rocklab;
using namespace rocklab::experiments;
using geometry::Vec3;

namespace {

const std::string kMovie = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/zwick-hcp-movie.toml";

/// Two touching balls of the rock joined by one bond, intact or broken.
struct BondedPair {
  explicit BondedPair(bool intact) : bond_intact{static_cast<std::uint8_t>(intact)} {}
  sim::Snapshot snapshot() const {
    sim::Snapshot s;
    s.position = position;
    s.velocity = velocity;
    s.radius = radius;
    s.id = id;
    s.material = material;
    s.bond_a = bond_a;
    s.bond_b = bond_b;
    s.bond_intact = bond_intact;
    return s;
  }
  std::vector<Vec3> position{Vec3(-0.0025, 0, 0.02), Vec3(0.0025, 0, 0.02)};
  std::vector<Vec3> velocity{Vec3::Zero(), Vec3::Zero()};
  std::vector<double> radius{0.0025, 0.0025};
  std::vector<std::uint64_t> id{1, 2};
  std::vector<std::int32_t> material{0, 0};
  std::vector<std::uint32_t> bond_a{0}, bond_b{1};
  std::vector<std::uint8_t> bond_intact;
};

bool sameColour(const render::Rgb& x, const render::Rgb& y) {
  return x.r == y.r && x.g == y.g && x.b == y.b;
}

/// Pixels of a saturated colour (HSV saturation > 0.35 and value > 0.3): the
/// fragment hues; the grey specimen, the steel platens and the backdrop are not.
int saturatedPixels(const fs::path& png) {
  const cv::Mat bgr = cv::imread(png.string());
  REQUIRE_FALSE(bgr.empty());
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  cv::Mat mask;
  cv::inRange(hsv, cv::Scalar(0, 90, 77), cv::Scalar(180, 255, 255), mask);
  return cv::countNonZero(mask);
}

fs::path tempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("rocklab-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

}  // namespace

TEST_CASE(
    "crush movie: a broken bond gives its two balls different colours, an intact one the same",
    "[camera][fragments]") {
  const Scene scene = loadScene(kMovie);
  REQUIRE(scene.cameras.size() == 2);  // crush and burst
  for (const CameraSettings& c : scene.cameras) CHECK(c.colour_by == ColourBy::Fragment);
  const FrameBuilder by_fragment(scene, ColourBy::Fragment), by_material(scene, ColourBy::Material);
  const BondedPair intact(true), broken(false);
  const auto spheres = [&](const FrameBuilder& b, const BondedPair& p) {
    return b.describe(p.snapshot(), scene.model, {}, 0).spheres;
  };
  const auto whole = spheres(by_fragment, intact);
  REQUIRE(whole.size() == 2);
  CHECK(sameColour(whole[0].colour, whole[1].colour));
  // The intact specimen looks as it does coloured by material.
  CHECK(sameColour(whole[0].colour, spheres(by_material, intact)[0].colour));
  const auto split = spheres(by_fragment, broken);
  CHECK_FALSE(sameColour(split[0].colour, split[1].colour));
  CHECK(sameColour(split[0].colour, whole[0].colour));  // the largest (tie: lowest ball) keeps it
  CHECK(sameColour(split[1].colour, fragmentHue(1)));   // the other: the hue of its lowest ball
  // By material the broken pair is still one colour.
  const auto plain = spheres(by_material, broken);
  CHECK(sameColour(plain[0].colour, plain[1].colour));
  // Neighbouring lowest balls get far-apart hues.
  std::set<std::tuple<float, float, float>> hues;
  for (std::uint32_t k = 0; k < 8; ++k)
    hues.insert({fragmentHue(k).r, fragmentHue(k).g, fragmentHue(k).b});
  CHECK(hues.size() == 8);
}

TEST_CASE("crush movie: the platens are discs of the look's size and thickness", "[camera]") {
  const Scene scene = loadScene(kMovie);
  const FrameBuilder builder(scene);
  const BondedPair pair(true);
  const render::FrameDescription f = builder.describe(pair.snapshot(), scene.model, {}, 0);
  REQUIRE(f.meshes.size() == 2);  // both platens, as slabs
  CHECK(f.polygons.empty());
  for (const render::MeshInstance& m : f.meshes) {
    geometry::AABB box;
    for (const Vec3& v : m.mesh->vertices) box.extend(m.rotation * v + m.translation);
    const Vec3 size = box.hi - box.lo;
    CHECK(size.x() == Approx(0.08).epsilon(1e-3));  // disc diameter
    CHECK(size.y() == Approx(0.08).epsilon(1e-3));
    CHECK(size.z() == Approx(0.006));
  }
  // The slab lies behind each plane: below the bottom one, above the top one.
  CHECK(f.meshes[0].translation.z() == Approx(0.0));
  const auto z_range = [&](const render::MeshInstance& m) {
    double lo = 1, hi = -1;
    for (const Vec3& v : m.mesh->vertices) {
      lo = std::min(lo, (m.rotation * v + m.translation).z());
      hi = std::max(hi, (m.rotation * v + m.translation).z());
    }
    return std::pair{lo, hi};
  };
  CHECK(z_range(f.meshes[0]).second == Approx(0.0).margin(1e-12));
  CHECK(z_range(f.meshes[1]).first == Approx(0.05));
}

TEST_CASE("crush movie: a small crush is filmed by fragment, live and from run.h5",
          "[camera][fragments][zwick]") {
  // The 16 mm agglomerate of test_zwick closed 6x faster: seconds. The step (0.1 us)
  // divides the frame interval (1 ms) and the camera's (0.5 ms): the camera's frame 2k
  // and the stored frame k are the same step.
  const Scene scene =
      loadScene(kMovie, {"particles.0.diameter=0.016", "particles.0.position=[0,0,0.009]",
                         "experiment.platen_speed=0.05", "experiment.sample_interval=1e-5",
                         "cameras.0.frame_rate=2000", "cameras.0.still_interval=0.001",
                         "cameras.0.resolution=[320,240]", "cameras.0.movie=false",
                         "cameras.0.timestamp=false", "cameras.0.scale_bar=false",
                         "output.frame_interval=0.001", "cameras.0.target=[0,0,0.008]",
                         "cameras.0.eye=[0,-0.15,0.012]", "timestep.dt=1e-7", "cameras.0.all_frames=true"});
  const fs::path dir = tempDir("crush-movie");
  RunOptions options;
  options.out_dir = dir;
  options.threads = 1;
  options.progress = false;
  std::ostringstream log;
  REQUIRE(runScene(scene, options, log) == kExitOk);
  INFO(log.str());
  std::vector<fs::path> stills;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().starts_with("crush_still_")) stills.push_back(e.path());
  std::sort(stills.begin(), stills.end());
  REQUIRE(stills.size() >= 2);
  // The intact specimen at the start is one grey piece; after the crush the
  // pieces broken off show in their hues.
  CHECK(saturatedPixels(stills.front()) == 0);
  CHECK(saturatedPixels(stills.back()) > 100);

  // rocklab render: the same colouring from the bond state of run.h5.
  sim::output::RunFileReader run(dir / "run.h5");
  REQUIRE(run.frameCount() >= 2);
  const sim::Snapshot& last = run.frame(run.frameCount() - 1);
  CHECK(last.bond_intact.size() == scene.bonds.size());
  std::size_t broken = 0;
  for (std::uint8_t b : last.bond_intact) broken += b == 0;
  CHECK(broken > 0);
  // The platens as the run placed them (results.json wall_placement), which
  // `rocklab render` draws: the top one closing from just above the specimen.
  std::ifstream results(dir / "results.json");
  const nlohmann::json r = nlohmann::json::parse(results);
  sim::Model placed = scene.model;
  REQUIRE(applyWallPlacement(r["wall_placement"], placed) == 2);
  const sim::Wall& top = placed.walls[1];
  CHECK(top.point.z() < 0.02);  // the scene says 0.05
  CHECK(top.motion.velocity.z() == Approx(-0.05));
  RenderRunOptions render;
  render.run_file = dir / "run.h5";
  render.out_dir = dir / "render";
  std::ostringstream render_log;
  REQUIRE(renderRun(render, render_log) == kExitOk);
  INFO(render_log.str());
  std::vector<fs::path> rendered;
  for (const auto& e : fs::directory_iterator(render.out_dir))
    if (e.path().filename().string().starts_with("crush_still_")) rendered.push_back(e.path());
  std::sort(rendered.begin(), rendered.end());
  REQUIRE(rendered.size() >= 2);
  CHECK(saturatedPixels(rendered.front()) == 0);
  CHECK(saturatedPixels(rendered.back()) > 100);
  // Pixel for pixel as the run drew the same steps (platens placed from results.json,
  // fragments coloured from the stored bond state).
  std::size_t compared = 0;
  for (std::size_t k = 0; k < run.frameCount(); ++k) {
    char live_name[32], again_name[32];
    std::snprintf(live_name, sizeof live_name, "frame_%06zu.png", 2 * k);
    std::snprintf(again_name, sizeof again_name, "frame_%06zu.png", k);
    const cv::Mat live = cv::imread((dir / "frames" / "crush" / live_name).string());
    if (live.empty()) break;  // the run's last stored frame (its last step) is no camera frame
    INFO(again_name);
    const cv::Mat again = cv::imread((render.out_dir / "frames" / "crush" / again_name).string());
    REQUIRE(again.size() == live.size());
    CHECK(cv::norm(live, again, cv::NORM_INF) == 0);
    ++compared;
  }
  CHECK(compared >= 10);
  fs::remove_all(dir);
}

TEST_CASE("crush movie: bad colour_by and plane_shape values are refused with the allowed ones",
          "[camera][scene]") {
  const auto error = [](const std::vector<std::string>& overrides) {
    try {
      loadScene(kMovie, overrides);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(error({"cameras.0.colour_by=\"cluster\""}),
             Catch::Contains("colour_by") && Catch::Contains("\"material\", \"fragment\""));
  // In a file: its name and line (a standalone scene: keys of an extending file lose their
  // file name today).
  const fs::path dir = tempDir("crush-movie-scene");
  fs::create_directories(dir);
  {
    std::ofstream bad(dir / "bad.toml");
    bad << "[scene]\nname = \"x\"\nend_time = 0.1\n[materials.rock]\ndensity = 2700\n[[cameras]]\n"
        << "name = \"side\"\nfov_deg = 20\neye = [0, -0.3, 0.02]\ntarget = [0, 0, 0.02]\n"
        << "colour_by = \"cluster\"\n";
  }
  try {
    loadScene(dir / "bad.toml");
    FAIL("accepted");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("bad.toml:11") && Catch::Contains("colour_by") &&
                             Catch::Contains("\"cluster\"") &&
                             Catch::Contains("allowed: \"material\", \"fragment\""));
  }
  fs::remove_all(dir);
  CHECK_THAT(error({"walls.top.plane_shape=\"hexagon\""}),
             Catch::Contains("plane_shape") && Catch::Contains("\"square\", \"disc\""));
  CHECK_THAT(error({"walls.top.plane_thickness=-0.001"}), Catch::Contains("plane_thickness"));
  CHECK(loadScene(kMovie, {"cameras.0.colour_by=\"material\""}).cameras[0].colour_by ==
        ColourBy::Material);
}
