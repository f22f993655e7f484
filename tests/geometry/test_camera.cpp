#include <catch2/catch.hpp>

#include <stdexcept>
#include <string>

#include "rocklab/geometry/camera.h"

using namespace rocklab::geometry;

namespace {

// Runs validate() and returns the message (empty when valid).
std::string validationMessage(const Camera& c) {
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("camera projects with the OpenCV pinhole convention", "[geometry][camera]") {
  Camera c;
  c.fx = 1000;
  c.fy = 900;
  c.cx = 320;
  c.cy = 240;
  CHECK_NOTHROW(c.validate());
  // On the optical axis → principal point; x right, y down.
  CHECK((c.project(Vec3(0, 0, 2)) - Vec2(320, 240)).norm() < 1e-12);
  CHECK((c.project(Vec3(0.1, 0.05, 2)) - Vec2(320 + 1000 * 0.05, 240 + 900 * 0.025)).norm() < 1e-12);
  // Translation: the world origin 1 m in front of the camera.
  c.translation = Vec3(0, 0, 1);
  CHECK((c.project(Vec3::Zero()) - Vec2(320, 240)).norm() < 1e-12);
  CHECK(c.position().isApprox(Vec3(0, 0, -1)));
}

TEST_CASE("camera distortion follows OpenCV k1 k2 and inverts", "[geometry][camera]") {
  Camera c;
  c.k1 = -0.2;
  c.k2 = 0.05;
  const Vec2 n(0.3, -0.2);
  const double r2 = n.squaredNorm();
  CHECK((c.distort(n) - n * (1 + c.k1 * r2 + c.k2 * r2 * r2)).norm() < 1e-15);
  CHECK((c.undistort(c.distort(n)) - n).norm() < 1e-12);
  // Projection = distort, then intrinsics.
  const Vec3 p(0.3, -0.2, 1.0);
  const Vec2 d = c.distort(n);
  CHECK((c.project(p) - Vec2(c.fx * d.x() + c.cx, c.fy * d.y() + c.cy)).norm() < 1e-12);
  // pixelRay is the inverse of project.
  const Vec3 ray = c.pixelRay(c.project(p));
  CHECK((ray - p.normalized()).norm() < 1e-12);
}

TEST_CASE("camera lookAt gives a proper rotation looking at the target", "[geometry][camera]") {
  Camera c = Camera::withFieldOfView(640, 480, 60.0);
  const Vec3 eye(0.5, -1.0, 0.3), target(0.1, 0.2, 0.05);
  c.lookAt(eye, target, Vec3(0, 0, 1));
  CHECK(validationMessage(c).empty());
  CHECK((c.position() - eye).norm() < 1e-12);
  CHECK((c.project(target) - Vec2(c.cx, c.cy)).norm() < 1e-9);
  // World up appears up in the image (smaller v).
  CHECK(c.project(target + Vec3(0, 0, 0.01)).y() < c.cy);
  // Field of view: the image edge sees 30 degrees off axis.
  CHECK(c.fx == Approx(320.0 / std::tan(30.0 * 3.14159265358979323846 / 180.0)));
  CHECK_THROWS_AS(c.lookAt(eye, eye, Vec3(0, 0, 1)), std::invalid_argument);
  CHECK_THROWS_AS(c.lookAt(eye, eye + Vec3(0, 0, 1), Vec3(0, 0, 1)), std::invalid_argument);
}

TEST_CASE("camera validation names the bad field", "[geometry][camera]") {
  const Camera good;
  CHECK(validationMessage(good).empty());
  auto messageWith = [&](auto edit) {
    Camera c = good;
    edit(c);
    return validationMessage(c);
  };
  using Catch::Matchers::StartsWith;
  CHECK_THAT(messageWith([](Camera& c) { c.fx = 0; }), StartsWith("camera.fx"));
  CHECK_THAT(messageWith([](Camera& c) { c.fy = -5; }), StartsWith("camera.fy"));
  CHECK_THAT(messageWith([](Camera& c) { c.width = 0; }), StartsWith("camera.width"));
  CHECK_THAT(messageWith([](Camera& c) { c.height = -1; }), StartsWith("camera.height"));
  CHECK_THAT(messageWith([](Camera& c) { c.cx = std::nan(""); }), StartsWith("camera.cx"));
  CHECK_THAT(messageWith([](Camera& c) { c.rotation(0, 1) = 0.1; }), StartsWith("camera.rotation"));
  CHECK_THAT(messageWith([](Camera& c) { c.rotation(2, 2) = -1; }), StartsWith("camera.rotation"));  // reflection
  CHECK_THAT(messageWith([](Camera& c) { c.frameRate = 0; }), StartsWith("camera.frameRate"));
  CHECK_THAT(messageWith([](Camera& c) { c.exposureTime = 0.01; }), StartsWith("camera.exposureTime"));
  // A lens that folds over inside the image (r_d has a maximum below the corner radius).
  CHECK_THAT(messageWith([](Camera& c) { c.k1 = -2.0; c.fx = c.fy = 200; }), StartsWith("camera.k1"));
  CHECK_THROWS_AS(Camera::withFieldOfView(640, 480, 0.0), std::invalid_argument);
}
