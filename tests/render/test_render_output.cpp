// Image and movie output, overlays.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "render_scenes.h"
#include "rocklab/render/image_io.h"
#include "rocklab/render/movie.h"
#include "rocklab/render/overlay.h"
#include "rocklab/render/renderer.h"

using namespace rocklab::render;
using namespace rocklab::render::test;

namespace {

std::filesystem::path scratchDir(const char* name) {
  const auto dir = std::filesystem::path(ROCKLAB_BINARY_DIR) / "tests" / "render_scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

cv::Mat testFrame(int k) {
  cv::Mat m(120, 160, CV_8UC3, cv::Scalar(30, 30, 30));
  cv::circle(m, cv::Point(20 + 10 * k, 60), 12, cv::Scalar(40, 40, 220), cv::FILLED);
  return m;
}

}  // namespace

TEST_CASE("writePng writes atomically and round-trips the pixels", "[render][output]") {
  const auto dir = scratchDir("png");
  const cv::Mat image = testFrame(2);
  const auto path = dir / "frames" / "frame_000002.png";
  writePng(path, image);
  CHECK(std::filesystem::exists(path));
  CHECK_FALSE(std::filesystem::exists(path.string() + ".partial"));
  CHECK(cv::norm(cv::imread(path.string()), image, cv::NORM_INF) == 0);
  CHECK_THROWS(writePng(dir / "empty.png", cv::Mat()));
}

TEST_CASE("movie writer writes a readable file and reports its codec", "[render][output]") {
  const auto dir = scratchDir("movie");
  for (MovieCodec codec : {MovieCodec::Auto, MovieCodec::Mjpeg}) {
    std::filesystem::path written;
    std::string name;
    {
      MovieWriter movie(dir / (codec == MovieCodec::Auto ? "auto.mp4" : "mjpg.mp4"), cv::Size(160, 120), 25.0, codec);
      name = movie.codecName();
      for (int k = 0; k < 12; ++k) movie.write(testFrame(k));
      CHECK(movie.framesWritten() == 12);
      CHECK_THROWS(movie.write(cv::Mat(10, 10, CV_8UC3)));
      written = movie.close();
    }
    std::printf("movie codec: %s -> %s\n", name.c_str(), written.filename().c_str());
    CHECK(std::filesystem::exists(written));
    CHECK(std::filesystem::file_size(written) > 0);
    // Frames went to a .partial file first; none is left.
    for (const auto& entry : std::filesystem::directory_iterator(dir))
      CHECK(entry.path().string().find(".partial") == std::string::npos);
    cv::VideoCapture capture(written.string(), cv::CAP_FFMPEG);
    REQUIRE(capture.isOpened());
    int frames = 0;
    cv::Mat frame, first;
    while (capture.read(frame)) {
      if (frames == 0) first = frame.clone();
      ++frames;
    }
    CHECK(frames == 12);
    REQUIRE(!first.empty());
    // Lossy but close: mean difference of the first frame under 3 grey levels.
    cv::Mat diff;
    cv::absdiff(first, testFrame(0), diff);
    CHECK(cv::mean(diff.reshape(1))[0] < 3.0);
  }
  CHECK(MovieWriter(dir / "auto.mp4", cv::Size(160, 120), 25.0, MovieCodec::Mjpeg).path().extension() == ".avi");
}

TEST_CASE("overlays draw a time stamp and a true-length scale bar", "[render][output]") {
  const Camera camera = labCamera(kSceneView);
  cv::Mat image(camera.height, camera.width, CV_8UC3, cv::Scalar(0, 0, 0));
  drawTimestamp(image, 0.1234);
  CHECK(cv::countNonZero(image.reshape(1)) > 0);
  cv::Mat bar(camera.height, camera.width, CV_8UC3, cv::Scalar(0, 0, 0));
  const double depth = 0.5, length = 50.0;  // 50 mm at 0.5 m: 80 px with fx = 800
  CHECK(drawScaleBar(bar, camera, depth, length) == length);
  // The bar is the widest run of white pixels in its row.
  cv::Mat grey;
  cv::cvtColor(bar, grey, cv::COLOR_BGR2GRAY);
  const int row = bar.rows - 8 - 4;
  int first = -1, last = -1;
  for (int u = 0; u < grey.cols; ++u)
    if (grey.at<unsigned char>(row, u) > 200) {
      if (first < 0) first = u;
      last = u;
    }
  CHECK(last - first == Approx(camera.fx * length * 1e-3 / depth).margin(0.5));
  CHECK(drawScaleBar(bar, camera, depth) == 50.0);  // auto: 1-2-5 length below a fifth of the width (80 mm)
}
