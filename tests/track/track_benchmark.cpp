// Detection + linking frames/s on rendered frames of ~7,000 grey pebbles and 20 red
// markers (a plain executable, not a ctest):
//   cmake --build build --target track_benchmark && ./build/tests/track_benchmark
// The frames are rendered first (not timed); then detectMarkers and Linker::add run
// over them repeatedly on one thread.
#include <chrono>
#include <cstdio>
#include <vector>

#include "rocklab/render/renderer.h"
#include "rocklab/track/detect.h"
#include "rocklab/track/link.h"
#include "track_scenes.h"

using namespace rocklab;
using namespace rocklab::track;
using namespace rocklab::track::test;

namespace {

void measure(int width, int height) {
  Camera camera = Camera::withFieldOfView(width, height, 50.0);
  camera.lookAt(Vec3(0.0, -0.75, 0.15), Vec3(0.0, 0.0, 0.15), Vec3(0, 0, 1));
  render::Renderer renderer(camera);
  // 10 frames, markers moving 1 mm per frame along −x.
  std::vector<cv::Mat> frames;
  for (int k = 0; k < 10; ++k) frames.push_back(renderer.render(benchmarkScene(0.001 * k)));

  const int passes = width > 1000 ? 10 : 30;
  std::size_t detections = 0, tracks = 0;
  double detectSeconds = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int pass = 0; pass < passes; ++pass) {
    Linker linker;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const auto d0 = std::chrono::steady_clock::now();
      const std::vector<Detection> ds = detectMarkers(frames[k]);
      detectSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - d0).count();
      detections += ds.size();
      linker.add(static_cast<int>(k), k / 500.0, ds);
    }
    tracks = linker.tracks().size();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double n = static_cast<double>(passes * frames.size());
  std::printf("%4dx%-4d: %7.1f frames/s detection + linking (%.2f ms/frame; detection alone %.2f ms/frame), "
              "%.1f detections/frame, %zu tracks over 10 frames\n",
              width, height, n / seconds, 1e3 * seconds / n, 1e3 * detectSeconds / n, detections / n, tracks);
}

}  // namespace

int main() {
  const std::size_t spheres = benchmarkScene().spheres.size();
  std::printf("scene: %zu pebbles, 20 of them red markers\n", spheres);
  measure(640, 480);
  measure(1280, 1024);
  return 0;
}
