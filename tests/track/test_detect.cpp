// detectMarkers: sub-pixel centroids, empty frames, touching markers, slivers, settings.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "rocklab/track/detect.h"
#include "track_scenes.h"

using namespace rocklab::track;
using namespace rocklab::track::test;

namespace {

// The detection nearest to p, and its distance.
std::pair<const Detection*, double> nearestTo(const std::vector<Detection>& ds, cv::Point2d p) {
  const Detection* best = nullptr;
  double bestD = 1e300;
  for (const Detection& d : ds)
    if (cv::norm(d.centroid - p) < bestD) bestD = cv::norm(d.centroid - p), best = &d;
  return {best, bestD};
}

}  // namespace

TEST_CASE("a frame without markers gives no detection", "[track][detect]") {
  CHECK(detectMarkers(greyFrame({640, 480}, 2.0, 1)).empty());
  CHECK(detectMarkers(cv::Mat(480, 640, CV_8UC3, cv::Scalar(0, 0, 0))).empty());
  // A grey pebble-like disc and a blue one are not red.
  cv::Mat frame = greyFrame({320, 240}, 2.0, 2);
  drawDisc(frame, {100.3, 80.7}, 9.0, cv::Scalar(130, 140, 143));
  drawDisc(frame, {200.3, 150.7}, 9.0, cv::Scalar(190, 40, 35));
  CHECK(detectMarkers(frame).empty());
  CHECK_THROWS_WITH(detectMarkers(cv::Mat()), Catch::Contains("CV_8UC3"));
  CHECK_THROWS_WITH(detectMarkers(cv::Mat(10, 10, CV_8UC1)), Catch::Contains("CV_8UC3"));
}

TEST_CASE("antialiased red discs are found at their sub-pixel centres", "[track][detect]") {
  double worst = 0;
  for (int k = 0; k < 25; ++k) {
    cv::Mat frame = greyFrame({320, 240}, 2.0, 10 + k);
    const cv::Point2d centre(60.0 + 7.13 * k, 50.0 + 5.37 * k);
    const double radius = 5.0 + 0.2 * k;
    drawDisc(frame, centre, radius);
    const std::vector<Detection> ds = detectMarkers(frame);
    REQUIRE(ds.size() == 1);
    const double error = cv::norm(ds[0].centroid - centre);
    INFO("centre " << centre << " radius " << radius << " found " << ds[0].centroid);
    CHECK(error < 0.05);
    // cv::circle's antialiased disc is about half a pixel wider than asked (its
    // coverage sums to π (r + 0.5)²); pixels above a third of coverage count.
    CHECK(ds[0].radius_px == Approx(radius + 0.5).margin(0.25));
    CHECK(ds[0].fill > 0.8);
    worst = std::max(worst, error);
  }
  std::printf("synthetic discs (radius 5-10 px, noise 2 grey levels): worst centroid error %.4f px\n", worst);
}

TEST_CASE("two touching markers are split into two detections", "[track][detect]") {
  cv::Mat frame = greyFrame({400, 300}, 2.0, 7);
  const double r = 8.0;
  // Single markers set the median area; one pair touching side by side and one
  // pair touching on a diagonal.
  for (int k = 0; k < 5; ++k) drawDisc(frame, {40.0 + 70.0 * k + 0.3, 40.4}, r);
  const cv::Point2d a(100.2, 150.6), b(a.x + 2 * r, a.y);
  const cv::Point2d c(250.7, 200.1), d(c.x + 1.9 * r / std::sqrt(2.0), c.y + 1.9 * r / std::sqrt(2.0));
  for (const cv::Point2d& p : {a, b, c, d}) drawDisc(frame, p, r);
  // A big marker (2.5 times the area) is round: one detection, not split.
  const cv::Point2d big(330.4, 120.3);
  drawDisc(frame, big, 1.6 * r);
  const std::vector<Detection> ds = detectMarkers(frame);
  CHECK(ds.size() == 10);
  CHECK(nearestTo(ds, big).second < 0.05);
  double worst = 0;
  for (const cv::Point2d& p : {a, b, c, d}) {
    const auto [near, distance] = nearestTo(ds, p);
    REQUIRE(near != nullptr);
    INFO("marker " << p << " nearest detection " << near->centroid);
    CHECK(distance < 0.6);
    CHECK(near->area_px == Approx(std::numbers::pi * r * r).epsilon(0.2));
    worst = std::max(worst, distance);
  }
  std::printf("touching markers split (k-means on pixels, distance-transform seeds): worst centroid error %.3f px\n", worst);

  // Without splitting (ratio above the pair's area) a pair is one detection at its middle.
  DetectorSettings noSplit;
  noSplit.split_ratio = 3.0;
  noSplit.min_fill = 0.3;
  CHECK(detectMarkers(frame, noSplit).size() == 8);
}

TEST_CASE("markers of one size: a blob more than one covers is split whatever its fill or reported merged",
          "[track][detect]") {
  const double r = 8.0;
  DetectorSettings one_size;
  one_size.expected_area_px = std::numbers::pi * (r + 0.5) * (r + 0.5);  // the mask of one disc, antialiased rim included
  one_size.marker_max_ratio = 1.4;
  DetectorSettings any_size = one_size;
  any_size.marker_max_ratio = 0.0;
  // Two markers, one mostly behind the other (centres 0.8 r apart): about 1.5 marker
  // areas and round (fill ~0.75); the size rule (1.8, fill < 0.8) takes it for one.
  cv::Mat pair = greyFrame({200, 150}, 2.0, 11);
  const cv::Point2d a(100.3, 70.4), b(a.x + 0.8 * r, a.y + 0.1);
  for (const cv::Point2d& p : {a, b}) drawDisc(pair, p, r);
  const std::vector<Detection> whole = detectMarkers(pair, any_size);
  REQUIRE(whole.size() == 1);
  CHECK_FALSE(whole[0].merged);  // off: a big blob may be one big marker
  const std::vector<Detection> split = detectMarkers(pair, one_size);
  REQUIRE(split.size() == 2);
  for (const Detection& d : split) CHECK_FALSE(d.merged);
  CHECK(std::min(split[0].centroid.x, split[1].centroid.x) < 0.5 * (a.x + b.x));
  CHECK(std::max(split[0].centroid.x, split[1].centroid.x) > 0.5 * (a.x + b.x));

  // Four markers in a row cut at two tracks' predictions: two pieces of about two
  // markers each, more than one marker covers: merged, not one marker's position.
  cv::Mat row = greyFrame({200, 150}, 2.0, 12);
  std::vector<cv::Point2d> centres;
  for (int k = 0; k < 4; ++k) centres.emplace_back(60.2 + 1.6 * r * k, 75.3);
  for (const cv::Point2d& p : centres) drawDisc(row, p, r);
  const std::vector<cv::Point2d> predictions{centres[0], centres[1]};
  const std::vector<Detection> pieces = detectMarkers(row, one_size, predictions);
  REQUIRE(pieces.size() == 2);
  for (const Detection& d : pieces) CHECK(d.merged);
  for (const Detection& d : detectMarkers(row, any_size, predictions)) CHECK_FALSE(d.merged);

  // Off the optical axis a marker covers more (1 / cos θ): with the camera's focal
  // length a lone marker 1.5 times the axis' area at 45° is one marker, not merged.
  cv::Mat edge = greyFrame({200, 150}, 2.0, 13);
  drawDisc(edge, {150.2, 75.4}, std::sqrt(1.5) * (r + 0.5) - 0.5);
  DetectorSettings off_axis = one_size;
  off_axis.principal_point_px = {50.0, 75.0};
  off_axis.focal_px = 100.0;  // 100 px off the axis: θ = 45°, the reference grows by 1.41
  const std::vector<Detection> lone = detectMarkers(edge, off_axis);
  REQUIRE(lone.size() == 1);
  CHECK_FALSE(lone[0].merged);
  const std::vector<Detection> on_axis = detectMarkers(edge, one_size);
  CHECK((on_axis.size() == 2 || (on_axis.size() == 1 && on_axis[0].merged)));  // without it: over 1.4 areas
}

TEST_CASE("slivers and specks are rejected", "[track][detect]") {
  cv::Mat frame = greyFrame({320, 240}, 2.0, 3);
  drawDisc(frame, {160.4, 120.2}, 7.0);                                           // a marker
  cv::line(frame, {20, 200}, {300, 210}, kPaintedRed, 4, cv::LINE_AA);            // a red thread: fill ≈ 0.02
  cv::rectangle(frame, {30, 30}, {31, 31}, kPaintedRed, cv::FILLED);              // a 2×2 speck: opened away
  const std::vector<Detection> ds = detectMarkers(frame);
  REQUIRE(ds.size() == 1);
  CHECK(cv::norm(ds[0].centroid - cv::Point2d(160.4, 120.2)) < 0.05);
}

TEST_CASE("detector settings are validated with the field named", "[track][detect]") {
  DetectorSettings s;
  s.min_fill = 1.5;
  CHECK_THROWS_WITH(s.validate(), Catch::Contains("detector.min_fill"));
  s = {};
  s.split_ratio = 1.0;
  CHECK_THROWS_WITH(detectMarkers(greyFrame({8, 8}, 0, 1), s), Catch::Contains("detector.split_ratio"));
  s = {};
  s.max_area_px = 5;
  CHECK_THROWS_WITH(s.validate(), Catch::Contains("detector.max_area_px"));
  s = {};
  s.marker_max_ratio = 0.5;
  CHECK_THROWS_WITH(s.validate(), Catch::Contains("detector.marker_max_ratio"));
  s = {};
  s.focal_px = -1.0;
  CHECK_THROWS_WITH(s.validate(), Catch::Contains("detector.focal_px"));
}
