// What the image looks like: colours, determinism, the golden image, realism options, validation.
//
// Golden image: tests/render/golden/tiny_scene.png. After an intended change of
// the look, rewrite it with
//   ROCKLAB_UPDATE_GOLDEN=1 ./build/tests/render_tests "golden*"
// and look at the new PNG before committing it.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "render_scenes.h"
#include "rocklab/render/image_io.h"
#include "rocklab/render/renderer.h"

using namespace rocklab::render;
using namespace rocklab::render::test;

namespace {

std::string invalidMessage(const auto& make) {
  try {
    make();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("no GL context exists before a Renderer and none after it", "[render]") {
  CHECK(liveGlContexts() == 0);
  {
    Renderer renderer(smallSceneCamera(160, 120));
    CHECK(liveGlContexts() == 1);
    std::printf("GL_VERSION %s | GL_RENDERER %s | core profile %s\n", renderer.glVersion().c_str(),
                renderer.glRenderer().c_str(), renderer.coreProfile() ? "yes" : "no (compatibility fallback)");
    CHECK(!renderer.glVersion().empty());
    CHECK(!renderer.glRenderer().empty());
  }
  CHECK(liveGlContexts() == 0);
}

TEST_CASE("red markers and grey pebbles are separable by r minus g", "[render]") {
  const Camera camera = labCamera(kSceneView);
  const Vec3 marker(-0.03, 0, 0.02), pebble(0.03, 0, 0.02);
  const double radius = 0.015;
  FrameDescription frame;
  frame.spheres.push_back({marker, radius, kRedMarker, Vec3::Zero()});
  frame.spheres.push_back({pebble, radius, kGreyPebble, Vec3::Zero()});
  Renderer renderer(camera);
  for (double gain : {0.8, 1.0, 1.25}) {
    frame.lightGain = gain;
    const cv::Mat image = renderer.render(frame);
    // Interior pixels (1.5 px inside the silhouette) of each sphere, and the rest.
    const double rm = radius * camera.fx / camera.toCamera(marker).z() - 1.5;
    const double rp = radius * camera.fx / camera.toCamera(pebble).z() - 1.5;
    const Vec2 cm = camera.project(marker), cp = camera.project(pebble);
    int minMarker = 255, maxPebble = -255, maxBackground = -255;
    for (int v = 0; v < image.rows; ++v)
      for (int u = 0; u < image.cols; ++u) {
        const cv::Vec3b p = image.at<cv::Vec3b>(v, u);
        const int rg = int(p[2]) - int(p[1]);
        const double dm = (Vec2(u, v) - cm).norm(), dp = (Vec2(u, v) - cp).norm();
        if (dm < rm) minMarker = std::min(minMarker, rg);
        else if (dp < rp) maxPebble = std::max(maxPebble, rg);
        else if (dm > rm + 3 && dp > rp + 3) maxBackground = std::max(maxBackground, rg);
      }
    std::printf("gain %.2f: r-g marker >= %d, pebble <= %d, background <= %d\n", gain, minMarker, maxPebble, maxBackground);
    CHECK(minMarker > 40);
    CHECK(maxPebble < 15);
    CHECK(maxBackground < 15);
  }
}

TEST_CASE("two renders of the same frame are bitwise identical", "[render]") {
  const FrameDescription frame = tinyScene();
  Renderer a(labCamera(kSceneView, -0.1, 0.02));
  const cv::Mat first = a.render(frame);
  CHECK(cv::norm(first, a.render(frame), cv::NORM_INF) == 0);
  Renderer b(labCamera(kSceneView, -0.1, 0.02));  // a second context
  CHECK(cv::norm(first, b.render(frame), cv::NORM_INF) == 0);
  // With every realism option on, too (noise seeded by the frame index).
  Camera blurred = labCamera(kSceneView);
  blurred.exposureTime = 1.0 / 1000;
  RenderOptions lab;
  lab.motionBlur = true;
  lab.noiseSigma = 3.0;
  Renderer c(blurred, lab);
  FrameDescription moving = frame;
  for (auto& s : moving.spheres) s.velocity = Vec3(2.0, 0, -1.0);
  CHECK(cv::norm(c.render(moving), c.render(moving), cv::NORM_INF) == 0);
}

TEST_CASE("golden image of a tiny scene", "[render][golden]") {
  Renderer renderer(smallSceneCamera(160, 120));
  const cv::Mat image = renderer.render(tinyScene());
  const std::filesystem::path golden = std::filesystem::path(ROCKLAB_SOURCE_DIR) / "tests/render/golden/tiny_scene.png";
  if (const char* update = std::getenv("ROCKLAB_UPDATE_GOLDEN"); update && std::string(update) == "1") {
    writePng(golden, image);
    WARN("rewrote " << golden);
  }
  const cv::Mat expected = cv::imread(golden.string(), cv::IMREAD_COLOR);
  REQUIRE_FALSE(expected.empty());  // missing: run once with ROCKLAB_UPDATE_GOLDEN=1
  REQUIRE(expected.size() == image.size());
  cv::Mat diff;
  cv::absdiff(image, expected, diff);
  const double meanAbs = cv::mean(diff.reshape(1))[0];
  double maxAbs = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &maxAbs);
  std::printf("golden: mean |diff| %.4f, max %.0f grey levels\n", meanAbs, maxAbs);
  if (meanAbs >= 0.5) writePng(std::filesystem::path(ROCKLAB_BINARY_DIR) / "tests/render_golden_actual.png", image);
  CHECK(meanAbs < 0.5);
  // The mean alone lets a marker go missing or change colour (a sphere of r = 14 mm
  // covers ~100 of the 19,200 pixels: recoloured, the mean moves by ~0.3). Per
  // pixel: at most 20 pixels (the antialiased rims of a few spheres under another
  // Mesa) off by more than 24 grey levels; measured here: none off by more than one.
  cv::Mat worst;
  cv::reduce(diff.reshape(1, diff.rows * diff.cols), worst, 1, cv::REDUCE_MAX);
  CHECK(cv::countNonZero(worst > 24) <= 20);
  // Per sphere: the pixel at its centre keeps its colour within 12 grey levels.
  const Camera camera = smallSceneCamera(160, 120);
  for (const auto& sphere : tinyScene().spheres) {
    const Vec2 px = camera.project(sphere.centre);
    const cv::Point at(static_cast<int>(std::lround(px.x())), static_cast<int>(std::lround(px.y())));
    REQUIRE(cv::Rect(0, 0, image.cols, image.rows).contains(at));
    const cv::Vec3b a = image.at<cv::Vec3b>(at), b = expected.at<cv::Vec3b>(at);
    INFO("sphere at " << sphere.centre.transpose() << ", pixel " << at);
    for (int c = 0; c < 3; ++c) CHECK(std::abs(int(a[c]) - int(b[c])) <= 12);
  }
}

TEST_CASE("the compatibility fallback draws the same image as the core profile, to a rounding", "[render]") {
  RenderOptions compat;
  compat.profile = GlProfile::Compatibility;
  Renderer core(smallSceneCamera(160, 120)), fallback(smallSceneCamera(160, 120), compat);
  CHECK_FALSE(fallback.coreProfile());
  std::printf("fallback GL_VERSION %s\n", fallback.glVersion().c_str());
  // The same image up to one level at a few pixels: the two profiles compile the
  // shaders apart (llvmpipe may fuse a multiply-add in one and not the other), which
  // can round an antialiased edge pixel the other way.
  const cv::Mat a = core.render(tinyScene()), b = fallback.render(tinyScene());
  CHECK(cv::norm(a, b, cv::NORM_INF) <= 1);
  cv::Mat differs;
  cv::cvtColor(cv::abs(a - b) + cv::abs(b - a), differs, cv::COLOR_BGR2GRAY);
  CHECK(static_cast<std::size_t>(cv::countNonZero(differs)) <= a.total() / 1000);
}

TEST_CASE("transparent walls laid over on the CPU match blending them in GL to one level", "[render]") {
  const Camera camera = smallSceneCamera(160, 120);
  Renderer renderer(camera);
  // Every sphere of the tiny scene lies beyond its Perspex (the plane y = −0.07): laid over.
  const FrameDescription behind = tinyScene();
  const cv::Mat laid = renderer.render(behind);
  CHECK(renderer.transparentWallsLaidOver());
  // One more sphere on the near side of that plane, beside the wall (x > 0, where it
  // does not reach): the frame goes through GL's blending.
  const double r = 0.01;
  const Vec3 beside(0.15, -0.12, r);
  const Vec2 px = camera.project(beside);
  REQUIRE(cv::Rect(10, 10, camera.width - 20, camera.height - 20).contains(cv::Point(int(px.x()), int(px.y()))));
  FrameDescription front = behind;
  front.spheres.push_back({beside, r, kGreyPebble, Vec3::Zero()});
  const cv::Mat blended = renderer.render(front);
  CHECK_FALSE(renderer.transparentWallsLaidOver());
  // Everywhere but that sphere (a box twice its image), the same to one level.
  const int reach = static_cast<int>(std::ceil(2.0 * camera.fx * r / camera.toCamera(beside).z()));
  cv::Mat elsewhere(laid.size(), CV_8U, cv::Scalar(255));
  cv::rectangle(elsewhere, cv::Rect(int(px.x()) - reach, int(px.y()) - reach, 2 * reach + 1, 2 * reach + 1), cv::Scalar(0),
                cv::FILLED);
  const double worst = cv::norm(laid, blended, cv::NORM_INF, elsewhere);
  cv::Mat differs;
  cv::cvtColor(cv::abs(laid - blended) + cv::abs(blended - laid), differs, cv::COLOR_BGR2GRAY);
  differs.setTo(0, elsewhere == 0);
  std::printf("Perspex laid over vs blended in GL: max %.0f level, %d of %d pixels differ\n", worst,
              cv::countNonZero(differs), cv::countNonZero(elsewhere));
  CHECK(worst <= 1);
  // The Perspex tints what it covers in both: without it the left half changes.
  FrameDescription bare = behind;
  bare.polygons.pop_back();
  CHECK(cv::norm(laid, renderer.render(bare), cv::NORM_INF) > 10);
  // A sphere that reaches through the plane by a contact overlap (a twentieth of its
  // radius) is still seen through the wall; by a fifth, the frame goes through GL.
  for (const auto& [overlap, laidOver] : {std::pair{0.05, true}, std::pair{0.2, false}}) {
    FrameDescription touching = behind;
    touching.spheres.push_back({Vec3(-0.1, -0.07 + (1.0 - overlap) * r, r), r, kGreyPebble, Vec3::Zero()});
    (void)renderer.render(touching);
    INFO("overlap " << overlap << " r");
    CHECK(renderer.transparentWallsLaidOver() == laidOver);
  }
}

TEST_CASE("motion blur smears a moving sphere along its velocity about the same centre", "[render]") {
  Camera camera = labCamera(kSceneView);
  camera.exposureTime = 1.0 / 500;
  RenderOptions blur;
  blur.motionBlur = true;
  blur.motionBlurSubframes = 16;
  blur.ambient = 1.0f, blur.diffuse = 0.0f, blur.specular = 0.0f;
  FrameDescription frame;
  frame.background = {0, 0, 0};
  const Vec3 centre(0, 0, 0.05);
  const Vec3 velocity = 5.0 * camera.rotation.row(0).transpose();  // 5 m/s along image x
  frame.spheres.push_back({centre, 0.004, {1, 1, 1}, velocity});
  Renderer still(camera), moving(camera, blur);
  const cv::Mat a = still.render(frame), b = moving.render(frame);
  auto extent = [](const cv::Mat& m) {
    cv::Mat grey, mask;
    cv::cvtColor(m, grey, cv::COLOR_BGR2GRAY);
    const cv::Moments mo = cv::moments(grey);
    cv::threshold(grey, mask, 8, 255, cv::THRESH_BINARY);
    const cv::Rect box = cv::boundingRect(mask);
    return std::pair{Vec2(mo.m10 / mo.m00, mo.m01 / mo.m00), box};
  };
  const auto [ca, boxA] = extent(a);
  const auto [cb, boxB] = extent(b);
  const double smear = 5.0 * camera.exposureTime * camera.fx / camera.toCamera(centre).z();  // px
  std::printf("motion blur: smear %.2f px expected, width %d -> %d px, centroid shift %.3f px\n", smear, boxA.width,
              boxB.width, (ca - cb).norm());
  CHECK(std::abs((boxB.width - boxA.width) - smear) < 2.0);
  CHECK(std::abs(boxB.height - boxA.height) <= 1);
  CHECK((ca - cb).norm() < 0.1);
}

TEST_CASE("sensor noise is seeded by the frame index and has the asked sigma", "[render]") {
  RenderOptions noisy;
  noisy.noiseSigma = 4.0;
  noisy.noiseSeed = 7;
  Renderer clean(smallSceneCamera(160, 120)), sensor(smallSceneCamera(160, 120), noisy);
  FrameDescription frame = tinyScene();
  const cv::Mat reference = clean.render(frame);
  frame.index = 3;
  const cv::Mat n3 = sensor.render(frame);
  frame.index = 4;
  const cv::Mat n4 = sensor.render(frame);
  CHECK(cv::norm(n3, n4, cv::NORM_INF) > 0);
  frame.index = 3;
  CHECK(cv::norm(n3, sensor.render(frame), cv::NORM_INF) == 0);
  cv::Mat diff;
  cv::subtract(n3, reference, diff, cv::noArray(), CV_32F);
  cv::Scalar mean, sd;
  cv::meanStdDev(diff.reshape(1), mean, sd);
  CHECK(std::abs(mean[0]) < 0.2);
  CHECK(sd[0] == Approx(4.0).epsilon(0.05));
}

TEST_CASE("light gain scales the background and the lit colours", "[render]") {
  Renderer renderer(smallSceneCamera(160, 120));
  FrameDescription frame;
  frame.background = {0.2f, 0.4f, 0.6f};
  frame.lightGain = 0.5;
  const cv::Vec3b p = renderer.render(frame).at<cv::Vec3b>(0, 0);
  const cv::Vec3b expected(77, 51, 26);  // BGR of 0.5 × 255 × (0.6, 0.4, 0.2), rounded
  for (int ch = 0; ch < 3; ++ch) CHECK(std::abs(int(p[ch]) - int(expected[ch])) <= 1);
}

TEST_CASE("bad input throws std::invalid_argument naming the field", "[render]") {
  using Catch::Matchers::StartsWith;
  Camera noFocal = smallSceneCamera(160, 120);
  noFocal.fx = 0;
  CHECK_THAT(invalidMessage([&] { Renderer r(noFocal); }), StartsWith("camera.fx"));
  Camera empty = smallSceneCamera(160, 120);
  empty.height = 0;
  CHECK_THAT(invalidMessage([&] { Renderer r(empty); }), StartsWith("camera.height"));
  Camera skew = smallSceneCamera(160, 120);
  skew.rotation(0, 0) *= 1.01;
  CHECK_THAT(invalidMessage([&] { Renderer r(skew); }), StartsWith("camera.rotation"));
  RenderOptions options;
  options.farClip = options.nearClip;
  CHECK_THAT(invalidMessage([&] { Renderer r(smallSceneCamera(160, 120), options); }), StartsWith("render options.farClip"));
  CHECK(liveGlContexts() == 0);  // nothing was created for invalid input

  Renderer renderer(smallSceneCamera(160, 120));
  FrameDescription frame = tinyScene();
  frame.spheres[2].radius = -1;
  CHECK_THAT(invalidMessage([&] { renderer.render(frame); }), StartsWith("frame.spheres[2].radius"));
  frame = tinyScene();
  frame.polygons[1].vertices.resize(2);
  CHECK_THAT(invalidMessage([&] { renderer.render(frame); }), StartsWith("frame.polygons[1].vertices"));
  CHECK_THAT(invalidMessage([&] { renderer.setCamera(noFocal); }), StartsWith("camera.fx"));
}

TEST_CASE("the cached wall layer follows wall and camera changes", "[render]") {
  Renderer renderer(smallSceneCamera(160, 120));
  FrameDescription frame = tinyScene();
  (void)renderer.render(frame);
  frame.polygons[0].colour = {0.7f, 0.2f, 0.2f};
  frame.meshes[0].translation = Vec3(-0.02, 0.0, 0.0);
  frame.background = {0.3f, 0.3f, 0.1f};
  CHECK(cv::norm(renderer.render(frame), Renderer(smallSceneCamera(160, 120)).render(frame), cv::NORM_INF) == 0);
  Camera moved = smallSceneCamera(160, 120);
  moved.lookAt(Vec3(0.15, -0.5, 0.3), Vec3(0.0, 0.0, 0.03), Vec3(0, 0, 1));
  renderer.setCamera(moved);
  CHECK(cv::norm(renderer.render(frame), Renderer(moved).render(frame), cv::NORM_INF) == 0);
}
