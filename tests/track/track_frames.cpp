// Profiling aid (not a ctest, not a benchmark): the track benchmark's frames.
//   track_frames write DIR   renders the benchmark's 10 frames at 640x480 and 1280x1024 to DIR/WxH_k.png
//   track_frames run DIR W H  detection + linking once over DIR/WxH_*.png (for callgrind: toggle-collect on
//                             rocklab::track::detectMarkers* and rocklab::track::Linker::add)
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "rocklab/render/renderer.h"
#include "rocklab/track/detect.h"
#include "rocklab/track/link.h"
#include "track_scenes.h"

using namespace rocklab;
using namespace rocklab::track;
using namespace rocklab::track::test;

namespace {

std::string name(const std::string& dir, int w, int h, int k) {
  return dir + "/" + std::to_string(w) + "x" + std::to_string(h) + "_" + std::to_string(k) + ".png";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "write") {
    for (const cv::Size size : {cv::Size(640, 480), cv::Size(1280, 1024)}) {
      Camera camera = Camera::withFieldOfView(size.width, size.height, 50.0);
      camera.lookAt(Vec3(0.0, -0.75, 0.15), Vec3(0.0, 0.0, 0.15), Vec3(0, 0, 1));
      render::Renderer renderer(camera);
      for (int k = 0; k < 10; ++k)
        cv::imwrite(name(argv[2], size.width, size.height, k), renderer.render(benchmarkScene(0.001 * k)));
    }
    return 0;
  }
  if (argc == 5 && std::string(argv[1]) == "run") {
    const int w = std::atoi(argv[3]), h = std::atoi(argv[4]);
    std::vector<cv::Mat> frames;
    for (int k = 0; k < 10; ++k) frames.push_back(cv::imread(name(argv[2], w, h, k)));
    Linker linker;
    std::size_t detections = 0;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const std::vector<Detection> ds = detectMarkers(frames[k]);
      detections += ds.size();
      linker.add(static_cast<int>(k), k / 500.0, ds);
    }
    std::printf("%zu detections, %zu tracks\n", detections, linker.tracks().size());
    return 0;
  }
  std::fprintf(stderr, "usage: track_frames write DIR | run DIR W H\n");
  return 2;
}
