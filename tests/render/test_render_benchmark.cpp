// Frames per second for 7,000 random spheres (hidden: not run by ctest).
//   ./build/tests/render_tests "[benchmark]"
#include <catch2/catch.hpp>

#include <chrono>
#include <cstdio>

#include "render_scenes.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/render/renderer.h"

using namespace rocklab::render;
using namespace rocklab::render::test;

namespace {

// 7,000 non-overlapping pebbles (radius 3–7 mm, one in ten a red marker, 18 % solid)
// in a 0.5 m wide, 0.16 m deep, 0.3 m high box on a floor, behind a Perspex wall:
// a chute seen from the side.
FrameDescription benchmarkScene() {
  rocklab::geometry::Rng rng(42);
  std::vector<double> radii(7000);
  for (double& r : radii) r = rng.uniform(0.003, 0.007);
  const auto centres = rocklab::geometry::randomNonOverlapping(radii, Vec3(-0.25, -0.08, 0.0), Vec3(0.25, 0.08, 0.3), {}, rng);
  FrameDescription f;
  for (std::size_t i = 0; i < centres.size(); ++i)
    f.spheres.push_back({centres[i], radii[i], i % 10 == 0 ? kRedMarker : kGreyPebble, Vec3::Zero()});
  f.polygons.push_back({{{-0.4, -0.1, 0}, {0.4, -0.1, 0}, {0.4, 0.1, 0}, {-0.4, 0.1, 0}}, {0.4f, 0.38f, 0.35f}, 1.0f});
  f.polygons.push_back({{{-0.4, 0.09, 0}, {0.4, 0.09, 0}, {0.4, 0.09, 0.35}, {-0.4, 0.09, 0.35}}, {0.3f, 0.32f, 0.36f}, 1.0f});
  f.polygons.push_back({{{-0.4, -0.09, 0}, {0.4, -0.09, 0}, {0.4, -0.09, 0.35}, {-0.4, -0.09, 0.35}}, kPerspex, 0.15f});
  return f;
}

void measure(const FrameDescription& frame, int width, int height, int msaa) {
  Camera camera = Camera::withFieldOfView(width, height, 50.0);
  camera.lookAt(Vec3(0.0, -0.75, 0.15), Vec3(0.0, 0.0, 0.15), Vec3(0, 0, 1));
  RenderOptions options;
  options.msaaSamples = msaa;
  Renderer renderer(camera, options);
  (void)renderer.render(frame);  // warm-up (shader compile, buffers)
  const int frames = width > 1000 ? 30 : 60;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < frames; ++k) (void)renderer.render(frame);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%zu spheres %dx%d msaa %d: %.1f frames/s (%.2f ms/frame, render + readback + BGR)\n", frame.spheres.size(),
              width, height, msaa, frames / seconds, 1e3 * seconds / frames);
}

}  // namespace

TEST_CASE("benchmark frames per second for 7000 spheres", "[.benchmark]") {
  const FrameDescription frame = benchmarkScene();
  REQUIRE(frame.spheres.size() == 7000);
  for (int msaa : {4, 0}) {
    measure(frame, 640, 480, msaa);
    measure(frame, 1280, 1024, msaa);
  }
}
