// The crusher's cut-away movie (issue 21): [cameras.cut] read from the scene, the
// chamber's walls drawn cut, a short crusher run with the camera writing frames,
// and `rocklab render` of a breakage run's run.h5 (its fragments' materials).
#include <H5Cpp.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/frame_builder.h"
#include "cli_support.h"
#include "crusher_support.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/render/renderer.h"
#include "rocklab/sim/output/run_file.h"

namespace fs = std::filesystem;
using namespace rocklab;
using namespace rocklab::experiments;
using geometry::Vec3;
using Catch::Matchers::Contains;

namespace {

const std::string kMovieScene = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/cone-crusher-movie.toml";

/// Pixels near a wall colour as lit (any shade of it: the hue within 10 degrees,
/// saturation above 0.3).
int pixelsOfHue(const cv::Mat& bgr, const render::Rgb& colour) {
  cv::Mat one(1, 1, CV_8UC3, cv::Scalar(colour.b * 255, colour.g * 255, colour.r * 255)), hsv1, hsv;
  cv::cvtColor(one, hsv1, cv::COLOR_BGR2HSV);
  const int hue = hsv1.at<cv::Vec3b>(0, 0)[0];  // OpenCV: 0-180
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  int n = 0;
  for (int v = 0; v < hsv.rows; ++v)
    for (int u = 0; u < hsv.cols; ++u) {
      const cv::Vec3b p = hsv.at<cv::Vec3b>(v, u);
      const int dh = std::abs(int(p[0]) - hue);
      n += std::min(dh, 180 - dh) <= 5 && p[1] > 77 && p[2] > 40;
    }
  return n;
}

const render::Rgb kMantle{0.30f, 0.42f, 0.62f}, kConcave{0.66f, 0.50f, 0.30f};

}  // namespace

TEST_CASE("crusher movie: the camera's cut faces it through the axis and opens the chamber to the mantle",
          "[camera][crusher][cutaway]") {
  const Scene scene = loadScene(kMovieScene);
  REQUIRE(scene.cameras.size() == 1);
  const CameraSettings& camera = scene.cameras[0];
  REQUIRE(camera.cut);
  // [cameras.cut] with no keys: through the target, the normal towards the eye across up.
  CHECK((camera.cut->point - Vec3(0, 0, 0.10)).norm() < 1e-15);
  CHECK((camera.cut->normal - Vec3(0, -1, 0)).norm() < 1e-12);
  // The base scene has no camera: it pays for no rendering.
  CHECK(loadScene(std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/cone-crusher-pbm.toml").cameras.empty());

  // The walls at t = 0, no balls. The crusher axis at z = 90 mm lies inside the
  // mantle: uncut, the ray to it meets the near concave's outside (bronze); cut,
  // it passes the removed half and meets the inside of the mantle's far half (blue).
  const FrameBuilder builder(scene);
  render::FrameDescription frame = builder.describe(sim::Snapshot{}, scene.model, {}, 0);
  REQUIRE(frame.meshes.size() >= 5);  // mantle, cap, lower and upper concave, feed bin
  render::Renderer renderer(camera.camera);
  const cv::Mat uncut = renderer.render(frame);
  frame.cut = camera.cut;
  const cv::Mat cut = renderer.render(frame);
  const auto at = [&](const cv::Mat& image, const Vec3& p) {
    const auto px = camera.camera.project(p);
    cv::Mat one(1, 1, CV_8UC3);
    one.at<cv::Vec3b>(0, 0) = image.at<cv::Vec3b>(static_cast<int>(px.y()), static_cast<int>(px.x()));
    return one;
  };
  CHECK(pixelsOfHue(at(uncut, Vec3(0, 0, 0.09)), kConcave) == 1);
  CHECK(pixelsOfHue(at(cut, Vec3(0, 0, 0.09)), kMantle) == 1);
  // Cut, far more of the mantle shows (its inside), and the concave still does.
  const int mantle_uncut = pixelsOfHue(uncut, kMantle), mantle_cut = pixelsOfHue(cut, kMantle);
  INFO("mantle pixels uncut " << mantle_uncut << ", cut " << mantle_cut);
  CHECK(mantle_cut > 2 * mantle_uncut + 5000);
  CHECK(pixelsOfHue(cut, kConcave) > 5000);
}

TEST_CASE("crusher movie: bad [cameras.cut] keys are refused by name", "[camera][crusher][cutaway]") {
  const auto error = [](const std::vector<std::string>& overrides) -> std::string {
    try {
      loadScene(kMovieScene, overrides);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "loaded";
  };
  CHECK_THAT(error({"cameras.chamber.cut.normal=[0, 0, 0]"}), Contains("cut.normal") && Contains("non-zero"));
  CHECK_THAT(error({"cameras.chamber.cut.offset=1"}), Contains("offset"));
  // The eye straight above the point (along up): no plane faces the camera unless one is given.
  CHECK_THAT(error({"cameras.chamber.cut.point=[0, -0.85, 0]"}), Contains("cut.normal") && Contains("is needed"));
  CHECK(error({"cameras.chamber.cut.normal=[1, 0, 0]", "cameras.chamber.cut.point=[0.01, 0, 0]"}) == "loaded");
  // A wedge: a second normal, non-zero and crossing the first plane.
  CHECK_THAT(error({"cameras.chamber.cut.wedge_normal=[0, 0, 0]"}), Contains("cut.wedge_normal") && Contains("non-zero"));
  CHECK_THAT(error({"cameras.chamber.cut.wedge_normal=[0, 2, 0]"}),
             Contains("cut.wedge_normal") && Contains("parallel"));  // the default normal is (0, -1, 0)
  const Scene wedge = loadScene(kMovieScene, {"cameras.chamber.cut.wedge_normal=[-3, 0, 0]"});
  REQUIRE(wedge.cameras[0].cut->wedge_normal);
  CHECK((*wedge.cameras[0].cut->wedge_normal - Vec3(-1, 0, 0)).norm() < 1e-15);
  CHECK_FALSE(loadScene(kMovieScene).cameras[0].cut->wedge_normal);
}

TEST_CASE("crusher movie: a short crusher run with the cut-away camera writes its frames, stills and movie",
          "[cli][crusher][camera][cutaway]") {
  // The tiny CI crusher run (crusher_support.h: six 8-9 mm balls, soft contacts, the
  // release at 0.02 s) on the movie scene, cut short at 0.3 s, filmed from t = 0 at
  // 50 frames/s with a still every 0.1 s; the breakage's step and fragment stiffness
  // as in the tiny breakage run (test_crusher_breakage.cpp).
  const fs::path out = test::scratchDir("crusher-movie");
  std::vector<std::string> args = test::tinyCrusherRunArgs(out.string(), 1, "cone-crusher-movie.toml");
  for (const char* s : {"scene.end_time=0.3", "cameras.chamber.start_time=0", "cameras.chamber.frame_rate=50",
                        "cameras.chamber.still_interval=0.1", "experiment.breakage.youngs_modulus=1e8",
                        "experiment.breakage.min_diameter=0.0079", "timestep.dt=7e-7"})
    args.insert(args.end(), {"--set", s});
  REQUIRE(test::cli(args) == 0);
  std::ifstream in(out / "results.json");
  const auto r = nlohmann::json::parse(in);
  REQUIRE(r["cameras"].size() == 1);
  const auto& c = r["cameras"][0];
  INFO(c.dump());
  CHECK(c["name"] == "chamber");
  CHECK(c["frames"].get<int>() >= 15);  // t = 0, 0.02, ..., 0.3
  CHECK(c["frames"].get<int>() <= 16);
  CHECK(c["stills"].get<int>() >= 3);
  CHECK(c["cut"]["normal"][1].get<double>() == Approx(-1.0));
  REQUIRE(c.contains("movie"));
  CHECK(fs::file_size(out / c["movie"].get<std::string>()) > 1000);
  const cv::Mat still = cv::imread((out / "chamber_still_000001.png").string());
  REQUIRE_FALSE(still.empty());
  CHECK(still.cols == 640);
  CHECK(pixelsOfHue(still, kMantle) > 5000);
  CHECK(pixelsOfHue(still, kConcave) > 5000);
  fs::remove_all(out);
}

TEST_CASE("crusher movie: rocklab render of a breakage run draws its stored frames as the run did, fragments in "
          "their feed's shade, and an old run.h5 without /materials is refused naming the file",
          "[cli][crusher][camera][cutaway][breakage]") {
  // The tiny breakage run (test_crusher_breakage.cpp: weak balls that break by 0.17 s)
  // on the movie scene to 0.25 s. The camera films every stored frame: 20 frames/s
  // and a frame every 0.05 s, at a step (0.5 us) that divides it, so the camera's
  // frames and the stored ones are the same steps (at another step they can be a
  // step apart, and differ by that step's motion). Every raw frame is written.
  const fs::path out = test::scratchDir("crusher-rerender");
  std::vector<std::string> args = test::tinyCrusherRunArgs(out.string(), 1, "cone-crusher-movie.toml");
  for (const char* s : {"scene.end_time=0.25", "experiment.breakage.q_ref=2e5",
                        "experiment.breakage.check_interval=2e-5", "experiment.breakage.youngs_modulus=1e8", "experiment.breakage.min_diameter=0.0079",
                        "timestep.dt=5e-7", "output.vtk=false", "cameras.chamber.start_time=0",
                        "cameras.chamber.frame_rate=20", "cameras.chamber.all_frames=true",
                        "cameras.chamber.resolution=[320,240]", "cameras.chamber.movie=false"})
    args.insert(args.end(), {"--set", s});
  REQUIRE(test::cli(args) == 0);
  std::ifstream in(out / "results.json");
  const auto r = nlohmann::json::parse(in);
  REQUIRE(r["crusher"]["breakage"]["events"].get<int>() >= 1);
  const int live_frames = r["cameras"][0]["frames"].get<int>();
  CHECK(live_frames == 5);  // t = 0, 0.05, ..., 0.2 (the run's last step, 0.25 s - dt, is not due)

  // The run stored the fragment classes it made, each made from its feed material.
  const Scene scene = loadScene(kMovieScene);
  const std::size_t own = scene.model.materials.size();
  std::size_t fragment_frames = 0;
  {
    sim::output::RunFileReader run(out / "run.h5");
    const auto& materials = run.materials();
    REQUIRE(materials.size() > own);
    for (std::size_t m = own; m < materials.size(); ++m) {
      CHECK(materials[m].made_from >= 0);
      CHECK(static_cast<std::size_t>(materials[m].made_from) < own);
    }
    // Drawn as the run drew them: in the colour of the material they were made from.
    sim::Model model = scene.model;
    model.materials = materials;
    const FrameBuilder builder(scene);
    for (std::size_t k = 0; k < run.frameCount(); ++k) {
      const sim::Snapshot& s = run.frame(k);
      const auto spheres = builder.describe(s, model, {}, k).spheres;
      bool fragments = false;
      for (std::size_t i = 0; i < s.material.size(); ++i) {
        const auto m = static_cast<std::size_t>(s.material[i]);
        if (m < own) continue;
        fragments = true;
        const render::Rgb feed = scene.material_colours[static_cast<std::size_t>(materials[m].made_from)];
        CHECK((spheres[i].colour.r == feed.r && spheres[i].colour.g == feed.g && spheres[i].colour.b == feed.b));
      }
      fragment_frames += fragments;
    }
  }
  REQUIRE(fragment_frames >= 1);

  // The re-render: every frame the run's camera drew, pixel for pixel.
  std::string log;
  REQUIRE(test::cliLogged({"render", (out / "run.h5").string(), "--out", (out / "render").string()}, log) == 0);
  INFO(log);
  for (int k = 0; k < live_frames; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06d.png", k);
    INFO(name);
    const cv::Mat live = cv::imread((out / "frames" / "chamber" / name).string());
    const cv::Mat again = cv::imread((out / "render" / "frames" / "chamber" / name).string());
    REQUIRE_FALSE(live.empty());
    REQUIRE(again.size() == live.size());
    CHECK(cv::norm(live, again, cv::NORM_INF) == 0);
  }

  // A file from before /materials (the same run without it) is refused with the file
  // and what it lacks, exit 2; its frames before the first breakage still render.
  const fs::path old = out / "old" / "run.h5";
  fs::create_directories(old.parent_path());
  fs::copy_file(out / "run.h5", old);
  H5::H5File(old.string(), H5F_ACC_RDWR).unlink("materials");
  CHECK(sim::output::RunFileReader(old).materials().empty());
  CHECK(test::cliLogged({"render", old.string()}, log) == 2);
  CHECK_THAT(log, Contains(old.string()) && Contains("material row") && Contains("no /materials") &&
                      Contains("Run the scene again"));
  CHECK_FALSE(fs::exists(old.parent_path() / "chamber_still_000000.png"));  // nothing written
  {
    std::vector<std::string> with_fragments;
    {
      sim::output::RunFileReader run(old);
      for (std::size_t k = 0; k < run.frameCount(); ++k) {
        const auto& m = run.frame(k).material;
        if (std::any_of(m.begin(), m.end(), [&](std::int32_t x) { return static_cast<std::size_t>(x) >= own; })) {
          char name[32];
          std::snprintf(name, sizeof name, "%06zu", k);
          with_fragments.push_back(name);
        }
      }
    }
    H5::H5File file(old.string(), H5F_ACC_RDWR);
    for (const std::string& name : with_fragments) file.openGroup("frames").unlink(name);
  }
  CHECK(test::cliLogged({"render", old.string()}, log) == 0);
  const cv::Mat first = cv::imread((old.parent_path() / "frames" / "chamber" / "frame_000000.png").string());
  REQUIRE_FALSE(first.empty());
  CHECK(cv::norm(first, cv::imread((out / "frames" / "chamber" / "frame_000000.png").string()), cv::NORM_INF) == 0);
  fs::remove_all(out);
}
