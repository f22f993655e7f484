// The cut-away (FrameDescription::cut): wall pixels beyond the plane are discarded,
// spheres whose centre lies beyond it are dropped. Checked against ray casts of the
// same scene, not against a stored image.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "render_scenes.h"
#include "rocklab/render/renderer.h"

using namespace rocklab::render;
using namespace rocklab::render::test;

namespace {

constexpr Rgb kBoxRed{0.80f, 0.15f, 0.10f};
constexpr Rgb kBackGreen{0.10f, 0.75f, 0.15f};
constexpr Rgb kFarBlue{0.10f, 0.20f, 0.85f};

const Vec3 kBoxLo(-0.08, -0.08, 0.0), kBoxHi(0.08, 0.08, 0.10);

/// A closed box in front of a large green wall (the plane y = 0.3).
FrameDescription boxScene() {
  FrameDescription f;
  f.background = {0, 0, 0};
  f.polygons.push_back({{{-2, 0.3, -2}, {2, 0.3, -2}, {2, 0.3, 2}, {-2, 0.3, 2}}, kBackGreen, 1.0f});
  f.meshes.push_back({boxMesh(kBoxLo, kBoxHi), Mat3::Identity(), Vec3::Zero(), kBoxRed, 1.0f});
  return f;
}

/// Entry and exit of the ray eye + t d through the box (slabs), if it hits.
std::optional<std::pair<double, double>> boxHits(const Vec3& eye, const Vec3& d) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-15) {
      if (eye[i] < kBoxLo[i] || eye[i] > kBoxHi[i]) return std::nullopt;
      continue;
    }
    double a = (kBoxLo[i] - eye[i]) / d[i], b = (kBoxHi[i] - eye[i]) / d[i];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (t0 > t1) return std::nullopt;
  return std::pair{t0, t1};
}

/// What the ray through pixel (u, v) sees first: the box, the green wall or the black
/// background (the wall cut away). The box is a shell: with a cut, its entry point is
/// drawn only when it is not beyond the plane, else its exit point (the inner face of
/// the far side); the wall y = 0.3 is cut as well.
enum class Seen { Box, Wall, Background };
Seen seen(const Camera& camera, double u, double v, const std::optional<CutPlane>& cut) {
  const Vec3 eye = camera.position();
  const Vec3 d = camera.pixelRay(Vec2(u, v));
  const auto kept = [&](double t) { return !cut || !cut->removes(eye + t * d); };
  if (const auto hits = boxHits(eye, d); hits && (kept(hits->first) || kept(hits->second))) return Seen::Box;
  const double tWall = (0.3 - eye.y()) / d.y();
  return tWall > 0 && kept(tWall) ? Seen::Wall : Seen::Background;
}

/// Pixels whose colour disagrees with the ray cast (red box, green wall, black
/// background), leaving out those within 1.5 px of an edge (antialiasing); counts
/// what the ray cast predicts.
struct Comparison {
  int mismatches = 0, box = 0, wall = 0, background = 0;
};
Comparison compare(const cv::Mat& image, const Camera& camera, const std::optional<CutPlane>& cut) {
  Comparison c;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u) {
      const Seen what = seen(camera, u, v, cut);
      bool edge = false;
      for (double du : {-1.5, 0.0, 1.5})
        for (double dv : {-1.5, 0.0, 1.5}) edge = edge || seen(camera, u + du, v + dv, cut) != what;
      if (edge) continue;
      const cv::Vec3b p = image.at<cv::Vec3b>(v, u);
      const bool red = p[2] > p[1] + 40, green = p[1] > p[2] + 40, black = p[0] + p[1] + p[2] == 0;
      switch (what) {
        case Seen::Box: ++c.box; c.mismatches += !red; break;
        case Seen::Wall: ++c.wall; c.mismatches += !green; break;
        case Seen::Background: ++c.background; c.mismatches += !black; break;
      }
    }
  return c;
}

}  // namespace

TEST_CASE("a cut-away removes the walls beyond its plane, pixel for pixel as a ray cast, and shows their inner faces",
          "[render][cutaway]") {
  const Camera camera = smallSceneCamera(320, 240);
  Renderer renderer(camera);
  FrameDescription frame = boxScene();

  // Without a cut: the box as a ray cast sees it.
  const Comparison whole = compare(renderer.render(frame), camera, std::nullopt);
  CHECK(whole.mismatches == 0);
  REQUIRE(whole.box > 5000);

  // A tilted plane through the box: the part towards the camera and the left goes.
  CutPlane cut;
  cut.point = Vec3(0.01, 0.0, 0.03);
  cut.normal = Vec3(-1.0, -0.6, 0.3);
  frame.cut = cut;
  const cv::Mat cutImage = renderer.render(frame);
  const Comparison clipped = compare(cutImage, camera, cut);
  CHECK(clipped.mismatches == 0);
  // The cut really removed box pixels (the wall shows there now) and kept some.
  CHECK(clipped.box > 1000);
  CHECK(clipped.box < whole.box - 2000);
  CHECK(clipped.background > 5000);  // the wall behind is cut where it lies beyond the plane
  CHECK(whole.background == 0);
  // Some of the box pixels are the inside of the far faces (the entry point is cut away).
  int inner = 0;
  const Vec3 eye = camera.position();
  for (int v = 0; v < camera.height; v += 2)
    for (int u = 0; u < camera.width; u += 2) {
      const auto hits = boxHits(eye, camera.pixelRay(Vec2(u, v)));
      if (hits && (eye + hits->first * camera.pixelRay(Vec2(u, v)) - cut.point).dot(cut.normal) > 0 &&
          seen(camera, u, v, cut) == Seen::Box)
        ++inner;
    }
  CHECK(inner > 100);

  // The cached wall layer follows the cut: switching it off gives the uncut image again.
  frame.cut.reset();
  const cv::Mat again = renderer.render(frame);
  Renderer fresh(camera);
  CHECK(cv::norm(again, fresh.render(frame), cv::NORM_INF) == 0);
  CHECK(cv::norm(again, cutImage, cv::NORM_INF) > 0);
}

TEST_CASE("a wedge cut-away removes only what lies beyond both planes, pixel for pixel as a ray cast",
          "[render][cutaway]") {
  const Camera camera = smallSceneCamera(320, 240);
  Renderer renderer(camera);
  FrameDescription frame = boxScene();
  const int wholeBox = compare(renderer.render(frame), camera, std::nullopt).box;

  // The front-left quarter of the box (x < 0 and y < 0, towards the camera at
  // x = 0.1, y = -0.6) goes; the plane x = 0 alone would take the whole left half.
  CutPlane half;
  half.point = Vec3(0.0, 0.0, 0.03);
  half.normal = Vec3(-2.0, 0.0, 0.0);  // any length
  CutPlane quarter = half;
  quarter.wedge_normal = Vec3(0.0, -1.0, 0.0);
  CHECK(quarter.removes(Vec3(-0.01, -0.01, 0.05)));
  CHECK_FALSE(quarter.removes(Vec3(-0.01, 0.01, 0.05)));  // beyond the first plane only
  CHECK_FALSE(quarter.removes(Vec3(0.01, -0.01, 0.05)));  // beyond the second only
  CHECK(half.removes(Vec3(-0.01, 0.01, 0.05)));

  frame.cut = quarter;
  const cv::Mat quarterImage = renderer.render(frame);
  const Comparison wedge = compare(quarterImage, camera, quarter);
  CHECK(wedge.mismatches == 0);
  frame.cut = half;
  const cv::Mat halfImage = renderer.render(frame);
  const Comparison halved = compare(halfImage, camera, half);
  CHECK(halved.mismatches == 0);
  // The quarter takes box pixels (the inner faces of the back-left show where the
  // front-left was), and the wall behind the kept back-left quarter stays: fewer
  // background pixels than the half-space cut leaves.
  CHECK(wedge.box > 1000);
  CHECK(cv::norm(quarterImage, halfImage, cv::NORM_INF) > 0);
  CHECK(wedge.background < halved.background);
  CHECK(wholeBox > wedge.box - 1);
  // The wall y = 0.3 lies beyond the first plane only where x < 0, never beyond the
  // second: the wedge leaves all of it, so nothing black shows.
  CHECK(wedge.background == 0);
}

TEST_CASE("a cut-away drops the spheres whose centre lies beyond the plane and shows what they hid", "[render][cutaway]") {
  const Camera camera = smallSceneCamera(320, 240);
  const Vec3 eye = camera.position();
  const Vec3 view = (Vec3(0.0, 0.0, 0.05) - eye).normalized();
  // A near red sphere wholly hiding a smaller far blue one on the same line of sight
  // (the culler drops the far one when nothing is cut).
  const Vec3 nearCentre = eye + 0.45 * view, farCentre = eye + 0.75 * view;
  FrameDescription frame;
  frame.background = {0, 0, 0};
  frame.spheres.push_back({nearCentre, 0.04, kBoxRed, Vec3::Zero()});
  frame.spheres.push_back({farCentre, 0.03, kFarBlue, Vec3::Zero()});
  // A third sphere off to the side whose centre lies 1 mm short of the plane: it
  // crosses the plane and is drawn whole.
  CutPlane cut;
  cut.point = eye + 0.6 * view;
  cut.normal = -view;  // the half towards the camera goes
  const Vec3 side = view.cross(Vec3::UnitZ()).normalized();
  const Vec3 crossing = cut.point + 0.001 * view + 0.09 * side;
  frame.spheres.push_back({crossing, 0.02, kBackGreen, Vec3::Zero()});

  Renderer renderer(camera);
  const Vec2 centrePixel = camera.project(nearCentre);
  const auto pixel = [&](const cv::Mat& image) {
    return image.at<cv::Vec3b>(static_cast<int>(std::lround(centrePixel.y())), static_cast<int>(std::lround(centrePixel.x())));
  };
  const auto greenPixels = [](const cv::Mat& image) {
    int n = 0;
    for (int v = 0; v < image.rows; ++v)
      for (int u = 0; u < image.cols; ++u) {
        const cv::Vec3b p = image.at<cv::Vec3b>(v, u);
        n += p[1] > p[2] + 40 && p[1] > p[0] + 40;
      }
    return n;
  };
  const cv::Mat whole = renderer.render(frame);
  const cv::Vec3b before = pixel(whole);
  CHECK(before[2] > before[0] + 60);  // red: the near sphere

  frame.cut = cut;
  const cv::Mat cutImage = renderer.render(frame);
  const cv::Vec3b after = pixel(cutImage);
  CHECK(after[0] > after[2] + 60);  // blue: the far sphere, no longer culled
  // The crossing sphere is drawn whole: the same green pixels as without the cut.
  const int green = greenPixels(whole);
  CHECK(green > 200);
  CHECK(greenPixels(cutImage) == green);
  // Nothing red is left.
  int red = 0;
  for (int v = 0; v < cutImage.rows; ++v)
    for (int u = 0; u < cutImage.cols; ++u) {
      const cv::Vec3b p = cutImage.at<cv::Vec3b>(v, u);
      red += p[2] > p[1] + 40 && p[2] > p[0] + 40;
    }
  CHECK(red == 0);

  // With a wedge normal for which the near sphere's centre is not beyond, it stays.
  cut.wedge_normal = side + 0.1 * view;  // the near centre lies 0.015 m short of the second plane
  REQUIRE_FALSE(cut.removes(nearCentre));
  frame.cut = cut;
  const cv::Vec3b kept = pixel(renderer.render(frame));
  CHECK(kept[2] > kept[0] + 60);  // red again
}

TEST_CASE("a cut-away with a zero or non-finite normal is refused", "[render][cutaway]") {
  Renderer renderer(smallSceneCamera(320, 240));
  FrameDescription frame = boxScene();
  frame.cut = CutPlane{Vec3::Zero(), Vec3::Zero(), std::nullopt};
  CHECK_THROWS_WITH(renderer.render(frame), Catch::Contains("frame.cut.normal"));
  frame.cut = CutPlane{Vec3(std::nan(""), 0, 0), Vec3::UnitX(), std::nullopt};
  CHECK_THROWS_WITH(renderer.render(frame), Catch::Contains("frame.cut.point"));
  frame.cut = CutPlane{Vec3::Zero(), Vec3::UnitX(), Vec3::Zero()};
  CHECK_THROWS_WITH(renderer.render(frame), Catch::Contains("frame.cut.wedge_normal"));
}
