// Frames per second for 7,000 spheres (a plain executable, not a ctest):
//   cmake --build build --target render_benchmark && ./build/tests/render_benchmark
// Prints wall-clock frames/s and the CPU time per frame summed over all threads
// (llvmpipe's rasteriser threads included): on a loaded machine the first drops,
// the second stays about the same.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>

#include "render_scenes.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/render/renderer.h"

using namespace rocklab::render;
using namespace rocklab::render::test;

namespace {

double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// 7,000 non-overlapping pebbles (radius 3–7 mm, one in ten a red marker, 18 % solid)
// in a 0.5 m wide, 0.16 m deep, 0.3 m high box on a floor, against a back wall and
// behind a Perspex wall: a chute seen from the side.
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
  (void)renderer.render(frame);  // warm-up: shader compile, buffers, the cached wall layer
  const int frames = width > 1000 ? 40 : 150;
  const double cpu0 = cpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < frames; ++k) (void)renderer.render(frame);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpuSeconds() - cpu0;
  std::printf("%zu spheres %4dx%-4d msaa %d: %6.1f frames/s (%6.2f ms/frame wall, %6.2f ms/frame CPU, all threads)\n",
              frame.spheres.size(), width, height, msaa, frames / wall, 1e3 * wall / frames, 1e3 * cpu / frames);
}

}  // namespace

int main() {
  const FrameDescription frame = benchmarkScene();
  if (frame.spheres.size() != 7000) {
    std::fprintf(stderr, "render_benchmark: placed only %zu spheres\n", frame.spheres.size());
    return 1;
  }
  {
    Renderer probe(Camera{});
    std::printf("%s | %s\n", probe.glVersion().c_str(), probe.glRenderer().c_str());
  }
  for (int msaa : {4, 0}) {
    measure(frame, 640, 480, msaa);
    measure(frame, 1280, 1024, msaa);
  }
  return 0;
}
