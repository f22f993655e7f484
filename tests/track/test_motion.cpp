// From pixels to velocities: the velocity-over-distance rule against closed
// forms, and a synthetic moving disc tracked end to end in pixels and, through
// a posed distorted camera, in metres.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "rocklab/track/detect.h"
#include "rocklab/track/link.h"
#include "rocklab/track/plane.h"
#include "rocklab/track/velocity.h"
#include "track_scenes.h"

using namespace rocklab::track;
using namespace rocklab::track::test;

TEST_CASE("velocity over distance matches the closed form of constant acceleration", "[track][velocity]") {
  // Travel along −x: s(t) = v0 t + a t² / 2 (plus a sideways drift that must not
  // count); it reaches level s at t(s) = (√(v0² + 2 a s) − v0) / a.
  const double v0 = 0.3, a = 4.0, onset = 0.002, distance = 0.1;
  auto timeAt = [&](double s) { return (std::sqrt(v0 * v0 + 2 * a * s) - v0) / a; };
  const double exact = (distance - onset) / (timeAt(distance) - timeAt(onset));
  const Vec3 start(0.4, 0.05, 0.01);
  auto position = [&](double t) { return Vec3(start.x() - (v0 * t + 0.5 * a * t * t), start.y() + 0.2 * t, start.z()); };

  // Samples every 2 ms with the two crossing times among them: the interpolation is exact there.
  std::vector<Vec3> world;
  std::vector<double> time;
  const double tOn = timeAt(onset), tEnd = timeAt(distance);
  for (double t = 0; t < 0.3; t += 0.002) {
    if (t < tOn && t + 0.002 > tOn) time.push_back(tOn);
    if (t < tEnd && t + 0.002 > tEnd) time.push_back(tEnd);
    time.push_back(t);
  }
  std::sort(time.begin(), time.end());
  for (double t : time) world.push_back(position(t));
  const MarkerVelocity mv = velocityOverDistance(world, time, Vec3(-1, 0, 0), distance, onset);
  REQUIRE(mv.complete);
  const double relative = std::abs(mv.velocity - exact) / exact;
  std::printf("velocity over 100 mm, constant acceleration: %.12f m/s, exact %.12f m/s, relative error %.1e\n",
              mv.velocity, exact, relative);
  CHECK(relative < 1e-9);
  CHECK(mv.onset_time == Approx(tOn).epsilon(1e-9));
  CHECK(mv.end_time == Approx(tEnd).epsilon(1e-9));
  CHECK((mv.start_world - start).norm() == 0.0);

  // Uniform samples: each crossing time is off by at most the chord-to-curve gap
  // a dt² / 8 over the slope (≥ v0), so the relative error is bracketed by
  // 2 (a dt² / 8 v0) / (t_end − t_on): second order in the step.
  auto bound = [&](double dt) { return 2.0 * (a * dt * dt / (8.0 * v0)) / (tEnd - tOn) * 1.01; };
  auto uniformError = [&](double dt) {
    std::vector<Vec3> w;
    std::vector<double> ts;
    for (int k = 0; k * dt < 0.3; ++k) ts.push_back(k * dt), w.push_back(position(k * dt));
    return std::abs(velocityOverDistance(w, ts, Vec3(-2, 0, 0), distance, onset).velocity - exact) / exact;
  };
  const double e4 = uniformError(0.004), e2 = uniformError(0.002), e1 = uniformError(0.001);
  std::printf("uniform samples every 4, 2, 1 ms: relative error %.2e, %.2e, %.2e (bounds %.2e, %.2e, %.2e)\n", e4, e2,
              e1, bound(0.004), bound(0.002), bound(0.001));
  CHECK(e4 < bound(0.004));
  CHECK(e2 < bound(0.002));
  CHECK(e1 < bound(0.001));

  // Never reaching the distance: incomplete, velocity NaN; never moving: no onset either.
  const std::vector<Vec3> shortPath{start, start - Vec3(0.01, 0, 0), start - Vec3(0.05, 0, 0)};
  const MarkerVelocity partial = velocityOverDistance(shortPath, {0, 0.01, 0.02}, Vec3(-1, 0, 0), distance, onset);
  CHECK_FALSE(partial.complete);
  CHECK(std::isnan(partial.velocity));
  CHECK(partial.onset_time == Approx(0.002));
  const MarkerVelocity still = velocityOverDistance({start, start}, {0, 1}, Vec3(-1, 0, 0), distance, onset);
  CHECK(std::isnan(still.onset_time));
  CHECK_THROWS_WITH(velocityOverDistance({start}, {0, 1}, Vec3(-1, 0, 0), distance, onset), Catch::Contains("as many times"));
  CHECK_THROWS_WITH(velocityOverDistance({start}, {0}, Vec3(-1, 0, 0), 0.001, onset), Catch::Contains("onset < distance"));
}

TEST_CASE("a synthetic red disc at constant velocity is tracked to 0.5 percent", "[track][velocity]") {
  const DetectorSettings detector;
  SECTION("in pixels") {
    // 60 frames at 500 fps, (2.4, 0.9) px per frame: 2.563 px/frame = 1281.6 px/s.
    const cv::Point2d start(80.3, 150.6), step(2.4, 0.9);
    Linker linker;
    for (int k = 0; k < 60; ++k) {
      cv::Mat frame = greyFrame({400, 300}, 2.0, 100 + k);
      drawDisc(frame, start + k * step, 6.0);
      linker.add(k, k / kFrameRate, detectMarkers(frame, detector));
    }
    const std::vector<Track> tracks = linker.tracks();
    REQUIRE(tracks.size() == 1);
    REQUIRE(tracks[0].points.size() == 60);
    std::vector<Vec3> pixels;
    std::vector<double> times;
    for (const TrackPoint& p : tracks[0].points) pixels.emplace_back(p.pixel.x, p.pixel.y, 0.0), times.push_back(p.time);
    const MarkerVelocity mv = velocityOverDistance(pixels, times, Vec3(step.x, step.y, 0), 100.0, 2.0);
    const double truth = cv::norm(step) * kFrameRate;
    const double relative = std::abs(mv.velocity - truth) / truth;
    std::printf("synthetic disc, pixels: %.3f px/s tracked, %.3f px/s true, error %.4f %%\n", mv.velocity, truth, 100 * relative);
    REQUIRE(mv.complete);
    CHECK(relative < 0.005);
  }
  SECTION("in metres through a posed camera with barrel distortion") {
    // The disc is drawn where the camera sees a point sliding along −x on the base
    // (z = 0) at 1.2 m/s; the tracker takes the pixels back to that plane.
    const Camera camera = labCamera(kObliqueChuteView, -0.1);
    const Vec3 start(0.06, 0.01, 0.0), velocity(-1.2, 0.0, 0.0);
    Linker linker;
    for (int k = 0; k < 60; ++k) {
      cv::Mat frame = greyFrame({camera.width, camera.height}, 2.0, 200 + k);
      const Vec2 px = camera.project(start + velocity * (k / kFrameRate));
      drawDisc(frame, {px.x(), px.y()}, 6.0);
      linker.add(k, k / kFrameRate, detectMarkers(frame, detector));
    }
    const std::vector<Track> tracks = linker.tracks();
    REQUIRE(tracks.size() == 1);
    const MarkerVelocity mv = trackVelocity(tracks[0], camera, Vec3::Zero(), Vec3::UnitZ(), Vec3(-1, 0, 0), 0.1, 0.002);
    const double relative = std::abs(mv.velocity - 1.2) / 1.2;
    std::printf("synthetic disc, world: %.5f m/s tracked, 1.2 m/s true, error %.4f %%; start %.2f mm from the truth\n",
                mv.velocity, 100 * relative, 1e3 * (mv.start_world - start).norm());
    REQUIRE(mv.complete);
    CHECK(mv.track_id == 0);
    CHECK(relative < 0.005);
    CHECK((mv.start_world - start).norm() < 2e-4);
  }
}

TEST_CASE("travel counts from the reference time and earlier creep does not count", "[track][velocity]") {
  // A marker creeps 3 mm at 0.03 m/s before the gate opens at t_g = 0.1 s (not on a
  // sample), then moves off at constant acceleration from there: velocity over
  // 100 mm from its position at t_g, as the truth's from the gate.
  const double tg = 0.1013, creep = 0.03, a = 4.0, onset = 0.002, distance = 0.1;
  auto travel = [&](double t) { return t < tg ? creep * (t - tg) : creep * (t - tg) + 0.5 * a * (t - tg) * (t - tg); };
  std::vector<Vec3> world;
  std::vector<double> time;
  for (double t = 0.0; t < 0.5; t += 0.0005) time.push_back(t), world.push_back(Vec3(0.4 - travel(t), 0.0, 0.02));
  auto timeAt = [&](double s) { return tg + (std::sqrt(creep * creep + 2 * a * s) - creep) / a; };
  const double exact = (distance - onset) / (timeAt(distance) - timeAt(onset));
  const MarkerVelocity fromGate = velocityOverDistance(world, time, Vec3(-1, 0, 0), distance, onset, tg);
  const MarkerVelocity fromFirst = velocityOverDistance(world, time, Vec3(-1, 0, 0), distance, onset);
  std::printf("with 3 mm of creep before the gate: %.5f m/s from the gate, %.5f m/s from the first frame, exact %.5f\n",
              fromGate.velocity, fromFirst.velocity, exact);
  CHECK(fromGate.velocity == Approx(exact).epsilon(1e-3));
  CHECK(fromGate.start_world.x() == Approx(0.4 - travel(tg)).margin(1e-12));
  CHECK(fromFirst.velocity < 0.95 * exact);  // counting the creep biases the velocity low
  // A reference time after the last sample leaves nothing to measure.
  CHECK_FALSE(velocityOverDistance(world, time, Vec3(-1, 0, 0), distance, onset, 1.0).complete);
}

TEST_CASE("a track measured through a merged detection gives no velocity", "[track][velocity]") {
  // Pixels along u at 500 px/s on a camera looking down at z = 0; the travel is
  // measured in metres on that plane.
  rocklab::geometry::Camera camera = rocklab::geometry::Camera::withFieldOfView(640, 480, 60.0);
  camera.lookAt(Vec3(0.0, 0.0, 1.0), Vec3(0.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0));
  Track track;
  track.id = 7;
  for (int k = 0; k < 200; ++k) track.points.push_back({k, k / kFrameRate, {120.0 + k, 240.0}});
  const Vec3 along = (rocklab::track::pointToWorld(camera, track.points.back(), Vec3::Zero(), Vec3::UnitZ()).value() -
                      rocklab::track::pointToWorld(camera, track.points.front(), Vec3::Zero(), Vec3::UnitZ()).value());
  auto measure = [&](const Track& t) { return trackVelocity(t, camera, Vec3::Zero(), Vec3::UnitZ(), along, 0.1, 0.002, 0.01); };
  const MarkerVelocity clean = measure(track);
  REQUIRE(clean.complete);
  CHECK_FALSE(clean.merged);
  // A merged point while measured (two markers in the blob): no velocity.
  Track during = track;
  during.points[20].merged = true;
  const MarkerVelocity withheld = measure(during);
  CHECK(withheld.merged);
  CHECK_FALSE(withheld.complete);
  CHECK(std::isnan(withheld.velocity));
  CHECK(withheld.track_id == 7);
  // Before the reference time, or after the travel reached its distance: not measured, kept.
  Track outside = track;
  outside.points[2].merged = true;  // 4 ms, the reference is at 10 ms
  const int last = static_cast<int>(std::ceil(clean.end_time * kFrameRate)) + 2;
  REQUIRE(last < 200);
  outside.points[static_cast<std::size_t>(last)].merged = true;
  const MarkerVelocity kept = measure(outside);
  CHECK_FALSE(kept.merged);
  CHECK(kept.velocity == Approx(clean.velocity).epsilon(1e-12));
}
