// The red mask (stage 1) against what it replaces: cv::cvtColor to HSV, two
// cv::inRange bands and their union, then the open on the whole image; bit for bit.
#include <catch2/catch.hpp>

#include <vector>

#include <opencv2/imgproc.hpp>

#include "detect_internal.h"
#include "rocklab/render/renderer.h"
#include "rocklab/track/detect.h"
#include "track_scenes.h"

using namespace rocklab::track;
using namespace rocklab::track::test;

namespace {

cv::Mat referencePixels(const cv::Mat& bgr, const DetectorSettings& s) {
  cv::Mat hsv, low, high;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  cv::inRange(hsv, cv::Scalar(0, s.saturation_min, s.value_min), cv::Scalar(s.hue_low_max, 255, 255), low);
  cv::inRange(hsv, cv::Scalar(s.hue_high_min, s.saturation_min, s.value_min), cv::Scalar(179, 255, 255), high);
  return low | high;
}

cv::Mat referenceMask(const cv::Mat& bgr, const DetectorSettings& s) {
  cv::Mat mask = referencePixels(bgr, s);
  if (s.open_kernel_px > 1)
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_RECT, cv::Size(s.open_kernel_px, s.open_kernel_px)));
  return mask;
}

// Rows [first, last + 1) of `mask` with a nonzero pixel; (0, 0) when none.
cv::Range rowsWithPixels(const cv::Mat& mask) {
  cv::Range rows(mask.rows, 0);
  for (int v = 0; v < mask.rows; ++v)
    if (cv::countNonZero(mask.row(v)) > 0) rows = cv::Range(std::min(rows.start, v), v + 1);
  return rows.start < rows.end ? rows : cv::Range(0, 0);
}

void requireSameMask(const cv::Mat& bgr, const DetectorSettings& s) {
  cv::Range rows;
  const cv::Mat pixels = detail::redPixels(bgr, s, rows);
  const cv::Mat expected = referencePixels(bgr, s);
  INFO("hue <= " << s.hue_low_max << " or >= " << s.hue_high_min << ", saturation >= " << s.saturation_min
                 << ", value >= " << s.value_min << ", open " << s.open_kernel_px);
  CHECK(cv::countNonZero(pixels != expected) == 0);
  CHECK(rows == rowsWithPixels(expected));
  const cv::Mat opened = detail::redMask(bgr, s, rows);
  CHECK(cv::countNonZero(opened != referenceMask(bgr, s)) == 0);
}

DetectorSettings bands(int hue_low_max, int hue_high_min, int saturation_min, int value_min) {
  DetectorSettings s;
  s.hue_low_max = hue_low_max;
  s.hue_high_min = hue_high_min;
  s.saturation_min = saturation_min;
  s.value_min = value_min;
  return s;
}

}  // namespace

TEST_CASE("the red mask equals cvtColor + inRange for every 8-bit colour", "[track][detect]") {
  // All 2^24 BGR colours, one per pixel; the settings: the defaults, the edges of
  // the red-only shortcut (bands within 30 of red), bands that take the green and
  // blue hue branches, and the extreme minima.
  cv::Mat all(4096, 4096, CV_8UC3);
  for (int i = 0; i < (1 << 24); ++i) all.at<cv::Vec3b>(i >> 12, i & 4095) = cv::Vec3b(i >> 16, (i >> 8) & 255, i & 255);
  for (const DetectorSettings& s : {DetectorSettings{}, bands(29, 151, 1, 1), bands(30, 150, 100, 40),
                                    bands(90, 91, 0, 0), bands(0, 179, 255, 255), bands(179, 0, 37, 211)}) {
    cv::Range rows;
    const cv::Mat pixels = detail::redPixels(all, s, rows);
    const cv::Mat expected = referencePixels(all, s);
    INFO("hue <= " << s.hue_low_max << " or >= " << s.hue_high_min << ", saturation >= " << s.saturation_min
                   << ", value >= " << s.value_min);
    CHECK(cv::countNonZero(pixels != expected) == 0);
    CHECK(cv::countNonZero(expected) > 0);
  }
}

TEST_CASE("the opened red mask equals the whole-image open on random, drawn and rendered frames", "[track][detect]") {
  // Random colours (most pixels fail, specks and threads for the open).
  cv::Mat random(240, 320, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(random, cv::RNG::UNIFORM, 0, 256);
  for (int kernel : {0, 3, 5}) {
    DetectorSettings s = bands(20, 160, 60, 30);
    s.open_kernel_px = kernel;
    requireSameMask(random, s);
  }
  // Markers cut by the top and bottom edges, and none at all.
  cv::Mat edges = greyFrame({320, 240}, 2.0, 8);
  drawDisc(edges, {50.3, 0.4}, 7.0);
  drawDisc(edges, {150.3, 238.8}, 7.0);
  drawDisc(edges, {250.3, 120.2}, 2.0);  // removed by the open
  requireSameMask(edges, DetectorSettings{});
  requireSameMask(greyFrame({320, 240}, 2.0, 9), DetectorSettings{});
  // The benchmark's rendered pebbles and markers.
  Camera camera = Camera::withFieldOfView(320, 240, 50.0);
  camera.lookAt(Vec3(0.0, -0.75, 0.15), Vec3(0.0, 0.0, 0.15), Vec3(0, 0, 1));
  const cv::Mat rendered = rocklab::render::Renderer(camera).render(benchmarkScene());
  requireSameMask(rendered, DetectorSettings{});
  cv::Range rows;
  CHECK(cv::countNonZero(detail::redMask(rendered, DetectorSettings{}, rows)) > 100);  // markers seen
}

TEST_CASE("components from runs are OpenCV's 8-connected components, numbered in raster order", "[track][detect]") {
  cv::RNG rng(11);
  std::vector<cv::Mat> masks;
  for (double density : {0.02, 0.3, 0.55, 1.0}) {  // specks, tangles, one big blob
    cv::Mat noise(97, 131, CV_32F);
    rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
    masks.push_back(noise < density);
  }
  masks.push_back(cv::Mat::zeros(40, 50, CV_8U));
  cv::Mat drawn = greyFrame({320, 240}, 2.0, 12);
  for (int k = 0; k < 12; ++k) drawDisc(drawn, {13.0 + 25.3 * k, 7.0 + 19.1 * k}, 4.0 + k % 5);
  cv::Range rows;
  masks.push_back(detail::redMask(drawn, DetectorSettings{}, rows));
  for (const cv::Mat& mask : masks) {
    const detail::Components mine = detail::labelComponents(mask);
    cv::Mat labels, stats, centroids;
    const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
    REQUIRE(mine.count() == count);
    // The same partition: each of our labels maps to one of OpenCV's and back.
    std::vector<int> to_opencv(static_cast<std::size_t>(count), -1), from_opencv(static_cast<std::size_t>(count), -1);
    std::vector<int> first_seen;  // our labels in raster order of first pixel
    bool same = true;
    for (int v = 0; v < mask.rows; ++v)
      for (int u = 0; u < mask.cols; ++u) {
        const int a = mine.label(u, v), b = labels.at<int>(v, u);
        if (a != 0 && to_opencv[static_cast<std::size_t>(a)] == -1) first_seen.push_back(a);
        int& ab = to_opencv[static_cast<std::size_t>(a)];
        int& ba = from_opencv[static_cast<std::size_t>(b)];
        if (ab == -1) ab = b;
        if (ba == -1) ba = a;
        same = same && ab == b && ba == a;
      }
    CHECK(same);
    for (std::size_t k = 0; k < first_seen.size(); ++k) CHECK(first_seen[k] == static_cast<int>(k) + 1);
    for (int a = 1; a < count; ++a) {
      const int b = to_opencv[static_cast<std::size_t>(a)];
      CHECK(mine.areas[static_cast<std::size_t>(a)] == stats.at<int>(b, cv::CC_STAT_AREA));
      CHECK(mine.boxes[static_cast<std::size_t>(a)] == cv::Rect(stats.at<int>(b, cv::CC_STAT_LEFT), stats.at<int>(b, cv::CC_STAT_TOP),
                                                               stats.at<int>(b, cv::CC_STAT_WIDTH), stats.at<int>(b, cv::CC_STAT_HEIGHT)));
    }
  }
}

TEST_CASE("the enclosing circle of the rows' end pixels is the one of all pixels", "[track][detect]") {
  // Discs, touching pairs (split pieces have rows with gaps) and random specks.
  cv::Mat frame = greyFrame({320, 240}, 2.0, 13);
  for (int k = 0; k < 8; ++k) drawDisc(frame, {20.0 + 37.3 * k, 30.0 + 21.7 * k}, 3.0 + 2.1 * k);
  drawDisc(frame, {150.0, 200.0}, 9.0);
  drawDisc(frame, {164.0, 203.0}, 9.0);
  cv::Range rows;
  const cv::Mat mask = detail::redMask(frame, DetectorSettings{}, rows);
  const detail::Components components = detail::labelComponents(mask);
  REQUIRE(components.count() == 10);
  std::vector<std::vector<cv::Point>> sets;
  for (int label = 1; label < components.count(); ++label) {
    const detail::Blob blob = detail::componentBlob(components, label, components.boxes[static_cast<std::size_t>(label)]);
    sets.push_back(blob.core);
    for (const detail::Blob& piece : detail::splitBlob(blob, 2, 9.0)) sets.push_back(piece.core);
  }
  cv::RNG rng(14);
  for (int k = 0; k < 20; ++k) {
    std::vector<cv::Point> specks(1 + k * 3);
    for (cv::Point& p : specks) p = {rng.uniform(0, 40), rng.uniform(0, 30)};
    sets.push_back(specks);
  }
  for (const std::vector<cv::Point>& points : sets) {
    cv::Point2f all_centre, ends_centre;
    float all_radius = 0, ends_radius = 0;
    cv::minEnclosingCircle(points, all_centre, all_radius);
    const std::vector<cv::Point> ends = detail::rowEnds(points);
    CHECK(ends.size() <= points.size());
    cv::minEnclosingCircle(ends, ends_centre, ends_radius);
    CHECK(ends_radius == Approx(all_radius).margin(1e-4));
    CHECK(cv::norm(ends_centre - all_centre) < 1e-3);
  }
}
