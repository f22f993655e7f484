// pixelToPlane against Camera::project, through four lenses.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <random>
#include <utility>

#include "rocklab/track/plane.h"
#include "track_scenes.h"

using namespace rocklab::track;
using namespace rocklab::track::test;

TEST_CASE("pixelToPlane inverts Camera::project", "[track][plane]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst = 0;
  for (const auto& [k1, k2] : {std::pair{0.0, 0.0}, std::pair{-0.1, 0.0}, std::pair{-0.25, 0.08}, std::pair{0.15, 0.0}}) {
    const Camera camera = labCamera(kObliqueChuteView, k1, k2);
    for (int trial = 0; trial < 200; ++trial) {
      // A random plane through a random point in front of the camera.
      const Vec3 point(0.1 * uniform(rng), 0.1 * uniform(rng), 0.05 * uniform(rng));
      const Vec3 normal = Vec3(0.3 * uniform(rng), 0.3 * uniform(rng), 1.0).normalized() * (trial % 2 ? 1.0 : -2.0);
      const Vec2 pixel = camera.project(point);
      if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > camera.width - 1 || pixel.y() > camera.height - 1) continue;
      const auto back = pixelToPlane(camera, {pixel.x(), pixel.y()}, point, normal);
      REQUIRE(back);
      worst = std::max(worst, (*back - point).norm());
    }
  }
  std::printf("pixelToPlane(project(x)) - x: worst %.2e m over 4 lenses\n", worst);
  CHECK(worst < 1e-9);

  // No intersection: a plane behind the camera, or one containing the ray.
  const Camera camera = labCamera(kObliqueChuteView, -0.1);
  const Vec3 behind = camera.position() - 0.5 * camera.pixelRay({320, 240});
  CHECK_FALSE(pixelToPlane(camera, {320, 240}, behind, camera.pixelRay({320, 240})));
  const Vec3 ray = camera.pixelRay({100, 100});
  CHECK_FALSE(pixelToPlane(camera, {100, 100}, camera.position(), ray.unitOrthogonal()));
}
