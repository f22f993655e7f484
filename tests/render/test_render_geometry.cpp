// Where things land: rendered sphere centroids against geometry::Camera::project
// and cv::projectPoints (with and without distortion), occlusion, transparency.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "render_scenes.h"
#include "rocklab/render/renderer.h"

using namespace rocklab::render;
using namespace rocklab::render::test;

namespace {

// cv::projectPoints with the camera's pose, intrinsics and (k1, k2, 0, 0).
Vec2 opencvProject(const Camera& c, const Vec3& world) {
  cv::Mat rotation(3, 3, CV_64F), rvec;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rotation.at<double>(i, j) = c.rotation(i, j);
  cv::Rodrigues(rotation, rvec);
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << c.translation.x(), c.translation.y(), c.translation.z());
  const cv::Mat k = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  const cv::Mat dist = (cv::Mat_<double>(4, 1) << c.k1, c.k2, 0, 0);
  std::vector<cv::Point2d> out;
  cv::projectPoints(std::vector<cv::Point3d>{{world.x(), world.y(), world.z()}}, rvec, tvec, k, dist, out);
  return Vec2(out[0].x, out[0].y);
}

struct Centroids {
  Vec2 mask;      // centroid of the pixels above the threshold
  Vec2 weighted;  // grey-level weighted centroid (the soft edge counts by coverage)
  int pixels;
};

// Centroids of the bright blob in a window around `near` (black background).
Centroids blobCentroids(const cv::Mat& bgr, const Vec2& near, int halfWindow, int threshold) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  double sx = 0, sy = 0, n = 0, wx = 0, wy = 0, w = 0;
  const int u0 = static_cast<int>(std::lround(near.x())), v0 = static_cast<int>(std::lround(near.y()));
  for (int v = std::max(0, v0 - halfWindow); v <= std::min(grey.rows - 1, v0 + halfWindow); ++v)
    for (int u = std::max(0, u0 - halfWindow); u <= std::min(grey.cols - 1, u0 + halfWindow); ++u) {
      const int g = grey.at<unsigned char>(v, u);
      if (g > threshold) sx += u, sy += v, n += 1;
      wx += g * u, wy += g * v, w += g;
    }
  return {Vec2(sx / n, sy / n), Vec2(wx / w, wy / w), static_cast<int>(n)};
}

// Centre of a sphere's image (an ellipse) for an undistorted camera. The
// silhouette cone (axis at angle θ from the optical axis, half-angle α = asin(r/d))
// meets the image plane between tan(θ − α) and tan(θ + α) along the radial line;
// the centre is their midpoint, slightly outward of the projected centre.
Vec2 ellipseCentre(const Camera& c, const Vec3& world, double radius) {
  const Vec3 p = c.toCamera(world);
  const Vec2 n(p.x() / p.z(), p.y() / p.z());
  const double rho = n.norm(), theta = std::atan(rho), alpha = std::asin(radius / p.norm());
  const Vec2 m = rho > 0 ? Vec2(n / rho * 0.5 * (std::tan(theta + alpha) + std::tan(theta - alpha))) : n;
  return Vec2(c.fx * m.x() + c.cx, c.fy * m.y() + c.cy);
}

}  // namespace

TEST_CASE("rendered sphere centroids land on Camera::project and cv::projectPoints", "[render][camera]") {
  // Distortion cases: none, barrel, barrel with k2, pincushion.
  const std::vector<std::pair<double, double>> lenses{{0.0, 0.0}, {-0.25, 0.08}, {-0.12, 0.0}, {0.15, 0.0}};
  // Target pixels (sub-pixel, centre and near the corners) at 0.4–0.7 m along their rays.
  const std::vector<std::pair<Vec2, double>> targets{
      {Vec2(322.3, 236.8), 0.55}, {Vec2(100.4, 80.7), 0.45}, {Vec2(560.25, 410.6), 0.6},
      {Vec2(600.8, 50.1), 0.7},   {Vec2(40.5, 440.33), 0.4}, {Vec2(250.0, 300.5), 0.5}};
  const double radiusPx = 8.0;  // image radius
  double worstMask = 0, worstWeighted = 0, worstOpenCv = 0, worstEllipse = 0;
  for (const auto& [k1, k2] : lenses) {
    const Camera camera = labCamera(kSceneView, k1, k2);
    RenderOptions flat;  // flat white discs: the weighted centroid sees coverage only
    flat.ambient = 1.0f;
    flat.diffuse = 0.0f;
    flat.specular = 0.0f;
    Renderer renderer(camera, flat);
    for (const auto& [pixel, depth] : targets) {
      const Vec3 centre = camera.position() + depth * camera.pixelRay(pixel);
      const double zc = camera.toCamera(centre).z();
      FrameDescription frame;
      frame.background = {0, 0, 0};
      const double radius = radiusPx * zc / camera.fx;
      frame.spheres.push_back({centre, radius, {1, 1, 1}, Vec3::Zero()});
      const cv::Mat image = renderer.render(frame);
      const Vec2 expected = camera.project(centre);
      const Vec2 viaOpenCv = opencvProject(camera, centre);
      const Centroids c = blobCentroids(image, expected, 16, 127);
      INFO("k1 " << k1 << " k2 " << k2 << " target " << pixel.transpose() << " expected " << expected.transpose()
                 << " mask " << c.mask.transpose() << " weighted " << c.weighted.transpose());
      CHECK((expected - pixel).norm() < 1e-6);
      CHECK((expected - viaOpenCv).norm() < 1e-6);
      CHECK(c.pixels > 150);  // ~π 8² = 201 pixels
      CHECK((c.mask - expected).norm() < 0.25);
      CHECK((c.weighted - expected).norm() < 0.25);
      CHECK((c.weighted - viaOpenCv).norm() < 0.25);
      if (std::getenv("ROCKLAB_RENDER_VERBOSE"))
        std::printf("k1 %+.2f k2 %+.2f pixel (%6.2f, %6.2f): mask error %.4f px, weighted %.4f px\n", k1, k2, pixel.x(),
                    pixel.y(), (c.mask - expected).norm(), (c.weighted - expected).norm());
      // Without distortion the image is an exact ellipse: its centre, not the
      // projected centre (up to 0.05 px away here), is where the weight must sit.
      if (!camera.hasDistortion()) {
        const double e = (c.weighted - ellipseCentre(camera, centre, radius)).norm();
        CHECK(e < 0.02);
        worstEllipse = std::max(worstEllipse, e);
      }
      worstMask = std::max(worstMask, (c.mask - expected).norm());
      worstWeighted = std::max(worstWeighted, (c.weighted - expected).norm());
      worstOpenCv = std::max(worstOpenCv, (expected - viaOpenCv).norm());
    }
  }
  std::printf("centroid error, worst over %zu lenses x %zu positions: threshold mask %.4f px, weighted %.4f px; "
              "weighted vs exact ellipse centre (k = 0) %.4f px; Camera::project vs cv::projectPoints %.2e px\n",
              lenses.size(), targets.size(), worstMask, worstWeighted, worstEllipse, worstOpenCv);
}

TEST_CASE("the depth test hides what is behind and the Perspex wall tints what it covers", "[render]") {
  const Camera camera = labCamera(kSceneView);
  Renderer renderer(camera);
  const Vec3 target(0.0, 0.0, 0.05);
  const Vec3 toCamera = (camera.position() - target).normalized();
  const Vec2 px = camera.project(target);
  auto at = [&](const cv::Mat& m) { return m.at<cv::Vec3b>(static_cast<int>(std::lround(px.y())), static_cast<int>(std::lround(px.x()))); };

  // A red marker behind a grey pebble on the same ray: the pixel is grey. Drawn in both orders.
  FrameDescription frame;
  frame.spheres.push_back({target, 0.01, kRedMarker, Vec3::Zero()});
  frame.spheres.push_back({target + 0.05 * toCamera, 0.01, kGreyPebble, Vec3::Zero()});
  const cv::Vec3b front = at(renderer.render(frame));
  std::swap(frame.spheres[0], frame.spheres[1]);
  CHECK(at(renderer.render(frame)) == front);
  CHECK(std::abs(int(front[2]) - int(front[1])) < 10);  // grey: r ≈ g

  // An opaque wall in front hides the spheres.
  const Vec3 n = toCamera, a = n.unitOrthogonal(), b = n.cross(a);
  const Vec3 w = target + 0.1 * n;
  FrameDescription walled = frame;
  walled.polygons.push_back({{w - 0.05 * a - 0.05 * b, w + 0.05 * a - 0.05 * b, w + 0.05 * a + 0.05 * b, w - 0.05 * a + 0.05 * b},
                             {0.2f, 0.6f, 0.2f}, 1.0f});
  const cv::Vec3b green = at(renderer.render(walled));
  CHECK(green[1] > green[2] + 40);

  // The same wall as Perspex (opacity α): the sphere shows through, blended.
  const float alpha = 0.3f;
  walled.polygons[0].opacity = alpha;
  const cv::Vec3b blended = at(renderer.render(walled));
  for (int ch = 0; ch < 3; ++ch) CHECK(std::abs(blended[ch] - ((1 - alpha) * front[ch] + alpha * green[ch])) < 2.5);
}

TEST_CASE("spheres cut by the image border and spheres wider than a point sprite are drawn whole", "[render]") {
  // A: the lab camera; B: the same view on a wider canvas, A's pixel (u, v) is B's (u + 60, v + 40).
  const Camera a = labCamera(kSceneView);
  Camera b = a;
  b.width += 120;
  b.height += 80;
  b.cx += 60;
  b.cy += 40;
  RenderOptions flat;
  flat.ambient = 1.0f, flat.diffuse = 0.0f, flat.specular = 0.0f;
  Renderer ra(a, flat), rb(b, flat);
  FrameDescription frame;
  frame.background = {0, 0, 0};
  // Half outside the left edge (a quad in A, a point sprite in B), and one 300 px wide (a quad in both).
  const Vec3 edge = a.position() + 0.5 * a.pixelRay(Vec2(-3.2, 200.4));
  frame.spheres.push_back({edge, 10.0 * 0.5 / a.fx, {1, 1, 1}, Vec3::Zero()});
  const Vec3 big = a.position() + 0.6 * a.pixelRay(Vec2(350.3, 260.7));
  const double bigRadius = 150.0 * a.toCamera(big).z() / a.fx;
  frame.spheres.push_back({big, bigRadius, {0.5f, 0.5f, 0.5f}, Vec3::Zero()});
  const cv::Mat ia = ra.render(frame), ib = rb.render(frame);
  // Same rays, so the same pixels (up to float rounding of the shifted principal point).
  CHECK(cv::norm(ia, ib(cv::Rect(60, 40, a.width, a.height)), cv::NORM_INF) <= 1);
  // The big sphere's grey-level weighted centroid sits on its ellipse centre.
  cv::Mat grey;
  cv::cvtColor(ib, grey, cv::COLOR_BGR2GRAY);
  cv::Mat bigOnly = grey.clone();
  bigOnly.colRange(0, 100).setTo(0);  // drop the edge sphere (B's columns 47-67)
  const cv::Moments m = cv::moments(bigOnly);
  const Vec2 centroid(m.m10 / m.m00, m.m01 / m.m00);
  const double error = (centroid - ellipseCentre(b, big, bigRadius)).norm();
  std::printf("big sphere (300 px, a quad): weighted centroid %.4f px from the ellipse centre\n", error);
  CHECK(error < 0.05);
}
