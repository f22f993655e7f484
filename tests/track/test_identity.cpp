// Identities through contact and loss: the prediction-seeded split of a merged
// blob, stitching across a gap, and the evaluation's swap count.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "rocklab/track/evaluate.h"
#include "rocklab/track/stitch.h"
#include "rocklab/track/tracker.h"
#include "track_scenes.h"

using namespace rocklab::track;
using namespace rocklab::track::test;

namespace {

constexpr double kRadius = 8.0;  // px

TrackerSettings settingsFor(double radius) {
  TrackerSettings s;
  s.detector.expected_area_px = std::numbers::pi * (radius + 0.5) * (radius + 0.5);
  s.link.max_distance_px = radius;
  s.link.max_missed_frames = 2;
  s.stitch.max_gap_frames = 20;
  s.stitch.max_distance_px = radius;
  return s;
}

// Two markers falling side by side; their gap closes until they overlap (centres
// 1.2 radii apart: one blob of 1.7 marker areas, below the size rule's 1.8) and
// opens again. Returns the pixel of marker `which` (0 left, 1 right) at frame k.
cv::Point2d fallingPair(int which, int k, int frames) {
  const double half = 0.5 * frames;
  const double apart = kRadius * (1.2 + 1.8 * std::abs(k - half) / half);  // 3 r → 1.2 r → 3 r
  return {160.0 + (which ? 0.5 : -0.5) * apart + 0.13 * k, 40.0 + 2.7 * k};
}

// The track (after stitching) whose first point is nearest p.
const Track& startingNear(const std::vector<Track>& tracks, cv::Point2d p) {
  const Track* best = &tracks.front();
  for (const Track& t : tracks)
    if (cv::norm(t.points.front().pixel - p) < cv::norm(best->points.front().pixel - p)) best = &t;
  return *best;
}

}  // namespace

TEST_CASE("two markers that touch and separate keep their identities", "[track][identity]") {
  constexpr int frames = 60;
  Tracker tracker(settingsFor(kRadius));
  int merged_frames = 0;
  for (int k = 0; k < frames; ++k) {
    cv::Mat frame = greyFrame({320, 240}, 2.0, 100 + k);
    for (int which : {0, 1}) drawDisc(frame, fallingPair(which, k, frames), kRadius);
    // Without predictions the overlapping pair is one detection (the size rule does not split it).
    if (detectMarkers(frame, tracker.settings().detector).size() == 1) ++merged_frames;
    tracker.add(k, k / kFrameRate, frame);
  }
  CHECK(merged_frames >= 4);  // the case this test is about happened
  const StitchResult result = tracker.finish();
  for (int which : {0, 1}) {
    const Track& t = startingNear(result.tracks, fallingPair(which, 0, frames));
    INFO("marker " << which << ": track " << t.id << " of " << result.tracks.size());
    CHECK(t.points.size() == frames);  // found in every frame, merged ones too
    double worst = 0;
    for (const TrackPoint& p : t.points) worst = std::max(worst, cv::norm(p.pixel - fallingPair(which, p.frame, frames)));
    CHECK(worst < 0.35 * kRadius);  // and it is this marker's piece all along, never the other's
  }
}

TEST_CASE("a marker hidden for some frames is re-found by stitching with its identity", "[track][identity]") {
  // Marker A moves right and is hidden for 12 frames (longer than the linker waits);
  // marker B moves in parallel two diameters below; marker C appears later one
  // diameter ahead of where A comes back, but not near A's extrapolation.
  constexpr int frames = 50, hide_from = 20, hide_to = 32;
  auto a = [](int k) { return cv::Point2d(40.0 + 3.1 * k, 100.2); };
  auto b = [](int k) { return cv::Point2d(40.0 + 3.1 * k, 100.2 + 4 * kRadius); };
  auto c = [](int k) { return cv::Point2d(40.0 + 3.1 * k + 3 * kRadius, 100.2 - 0.5 * kRadius); };
  Tracker tracker(settingsFor(kRadius));
  for (int k = 0; k < frames; ++k) {
    cv::Mat frame = greyFrame({320, 240}, 2.0, 200 + k);
    if (k < hide_from || k >= hide_to) drawDisc(frame, a(k), kRadius);
    drawDisc(frame, b(k), kRadius);
    if (k >= hide_to) drawDisc(frame, c(k), kRadius);
    tracker.add(k, k / kFrameRate, frame);
  }
  const StitchResult result = tracker.finish();
  REQUIRE(result.joins.size() == 1);
  CHECK(result.joins[0].gap_frames == hide_to - hide_from);
  CHECK(result.joins[0].miss_px < 1.0);
  const Track& ta = startingNear(result.tracks, a(0));
  CHECK(ta.points.size() == frames - (hide_to - hide_from));
  CHECK(cv::norm(ta.points.back().pixel - a(frames - 1)) < 0.5);
  CHECK(result.tracks.size() == 3);  // A (stitched), B, C
  CHECK(result.unresolved.empty());

  SECTION("a gap longer than the gate is not bridged") {
    StitchSettings s = tracker.settings().stitch;
    s.max_gap_frames = hide_to - hide_from - 1;
    TrackerSettings short_gate = tracker.settings();
    short_gate.stitch = s;
    Tracker again(short_gate);
    for (int k = 0; k < frames; ++k) {
      cv::Mat frame = greyFrame({320, 240}, 2.0, 200 + k);
      if (k < hide_from || k >= hide_to) drawDisc(frame, a(k), kRadius);
      drawDisc(frame, b(k), kRadius);
      again.add(k, k / kFrameRate, frame);
    }
    CHECK(again.finish().joins.empty());
    CHECK(again.finish().tracks.size() == 3);
  }
}

TEST_CASE("a track ended at an ambiguous match is stitched when its extrapolation decides it", "[track][identity]") {
  // Marker A moves right with a ±0.75 px zig-zag in v (the visible centroid of a
  // turning clump), so the linker's 2-point prediction misses it by 3 px each frame.
  // Marker N comes down across A's path and is hidden from frame 23 to 33; at frame
  // 25 its prediction passes 3.5 px from A, within 1/0.6 of A's own miss, so A's
  // track ends there (ambiguous) and A goes on as a new track. N's prediction is
  // not A's extrapolation (least squares over 8 frames: about 1 px off), so the
  // stitch joins A to its continuation and N to its reappearance.
  constexpr int frames = 42, crossing = 25, hidden_from = 23, hidden_to = 34, n_from = 10;
  auto a = [](int k) { return cv::Point2d(40.0 + 3.1 * k, 120.2 + (k % 2 ? -0.75 : 0.75)); };
  auto n = [&](int k) { return cv::Point2d(40.0 + 3.1 * crossing + 3.4, 120.2 + 6.0 * (k - crossing)); };
  auto visible = [&](int marker, int k) { return marker == 0 || (k >= n_from && (k < hidden_from || k >= hidden_to)); };
  TrackerSettings settings = settingsFor(kRadius);
  settings.link.ambiguity_ratio = 0.6;
  settings.stitch.ambiguity_ratio = 0.6;
  const rocklab::geometry::Camera camera = rocklab::geometry::Camera::withFieldOfView(320, 240, 60.0);
  std::vector<TruthMarker> truth(2);
  Tracker tracker(settings);
  for (int k = 0; k < frames; ++k) {
    cv::Mat frame = greyFrame({320, 240}, 2.0, 300 + k);
    for (int marker : {0, 1}) {
      if (!visible(marker, k)) continue;
      const cv::Point2d p = marker == 0 ? a(k) : n(k);
      drawDisc(frame, p, kRadius);
      const auto ray = camera.pixelRay({p.x, p.y});
      truth[static_cast<std::size_t>(marker)].points.push_back({k, p, ray / ray.z()});
    }
    tracker.add(k, k / kFrameRate, frame);
  }
  truth[1].id = 1;
  // The case this test is about happened: A's first track ended at an ambiguous match.
  REQUIRE(tracker.linker().ambiguousEnds().size() == 1);
  const StitchResult result = tracker.finish();
  CHECK(result.joins.size() == 2);
  CHECK(result.unresolved.empty());
  EvaluationSettings s;
  s.match_distance_px = kRadius;
  s.image_size = {320, 240};
  const TrackingEvaluation e = evaluateTracks(result.tracks, truth, camera, {0, 0, 1}, {0, 0, 1}, {}, s);
  CHECK(e.identity_swaps == 0);
  for (const MarkerScore& m : e.markers) {
    INFO("marker " << m.truth_id);
    CHECK(m.fraction_found == 1.0);
    CHECK(m.track_ids.size() == 1);  // one track from first to last frame: its identity kept
  }
  CHECK(result.tracks.size() == 2);
}

TEST_CASE("two tracks starting near an ended one are unresolved, not merged", "[track][identity]") {
  // Track 0 ends heading right; tracks 1 and 2 start equally near its extrapolation.
  std::vector<Track> tracks(3);
  for (int k = 0; k < 10; ++k) tracks[0].points.push_back({k, k * 0.002, {10.0 + 2 * k, 50.0}});
  tracks[1].id = 1, tracks[2].id = 2;
  for (int k = 15; k < 25; ++k) {
    tracks[1].points.push_back({k, k * 0.002, {10.0 + 2 * k, 47.0}});
    tracks[2].points.push_back({k, k * 0.002, {10.0 + 2 * k, 53.0}});
  }
  StitchSettings s;
  s.max_distance_px = 8.0;
  const StitchResult result = stitchTracks(tracks, s);
  CHECK(result.joins.empty());
  CHECK(result.tracks.size() == 3);
  CHECK(result.unresolved == std::vector<int>{0, 1, 2});
  // Track 0 ended at an ambiguous match: the same tests, still unresolved.
  const StitchResult ended_ambiguous = stitchTracks(tracks, s, {0});
  CHECK(ended_ambiguous.joins.empty());
  CHECK(ended_ambiguous.unresolved == std::vector<int>{0, 1, 2});
  // One of them clearly nearer: joined, whether track 0 ended ambiguous or not.
  for (TrackPoint& p : tracks[2].points) p.pixel.y = 58.0;
  for (const std::vector<int>& ambiguous : {std::vector<int>{}, std::vector<int>{0}}) {
    const StitchResult clear = stitchTracks(tracks, s, ambiguous);
    REQUIRE(clear.joins.size() == 1);
    CHECK(clear.joins[0].from_id == 0);
    CHECK(clear.joins[0].to_id == 1);
    CHECK(clear.tracks.size() == 2);
    CHECK(clear.tracks[0].points.size() == 20);
    CHECK(std::find(clear.unresolved.begin(), clear.unresolved.end(), 0) == clear.unresolved.end());
  }
  // An ambiguous end with no candidate after it stays reported.
  tracks.resize(1);
  CHECK(stitchTracks(tracks, s, {0}).unresolved == std::vector<int>{0});
  CHECK_THROWS_WITH(stitchTracks(tracks, StitchSettings{-1}), Catch::Contains("stitch.max_gap_frames"));
}

TEST_CASE("the evaluation counts identity swaps, losses and errors against the truth", "[track][identity]") {
  // Two markers 20 px apart moving right; the tracks follow them with a +0.25 px
  // bias in u, and exchange markers at frame 10.
  const rocklab::geometry::Camera camera = rocklab::geometry::Camera::withFieldOfView(320, 240, 60.0);
  std::vector<TruthMarker> truth(2);
  std::vector<Track> tracks(2);
  for (int m = 0; m < 2; ++m) {
    truth[m].id = 10 + m;
    tracks[m].id = m;
  }
  for (int k = 0; k < 20; ++k)
    for (int m = 0; m < 2; ++m) {
      const cv::Point2d p(100.0 + k, 100.0 + 20.0 * m);
      const auto ray = camera.pixelRay({p.x, p.y});
      truth[m].points.push_back({k, p, ray / ray.z()});  // on the plane z = 1 m
      if (k == 5 && m == 1) continue;                     // marker 1 not found in frame 5
      const int track = k < 10 ? m : 1 - m;
      tracks[track].points.push_back({k, k * 0.002, p + cv::Point2d(0.25, 0.0)});
    }
  EvaluationSettings s;
  s.match_distance_px = 5.0;
  s.image_size = {320, 240};
  const TrackingEvaluation e = evaluateTracks(tracks, truth, camera, {0, 0, 1}, {0, 0, 1},
                                              {{"x", rocklab::geometry::Vec3::UnitX()}}, s);
  CHECK(e.pairs == 39);
  CHECK(e.identity_swaps == 2);  // each track moved to the other marker once
  CHECK(e.track_changes == 2);
  CHECK(e.markers[0].frames_in_view == 20);
  CHECK(e.markers[1].frames_found == 19);
  CHECK(e.markers[1].fraction_found == Approx(0.95));
  CHECK(e.markers[0].track_ids == std::vector<int>{0, 1});
  CHECK(e.pixel_error[0].bias == Approx(0.25));
  CHECK(e.pixel_error[0].rms == Approx(0.25));
  CHECK(e.pixel_error[1].rms == Approx(0.0).margin(1e-12));
  CHECK(e.world_error[0].bias == Approx(0.25 / camera.fx).epsilon(0.01));  // 1 m away: px / fx
  // Every tracked u sits a quarter pixel right of a pixel centre: locked to one bin.
  CHECK(e.subpixel_u[7] == 39);
  // Without the swap: none counted.
  std::vector<Track> straight(2);
  for (int m = 0; m < 2; ++m) {
    straight[m].id = m;
    for (const TruthPoint& p : truth[m].points) straight[m].points.push_back({p.frame, 0.0, p.pixel});
  }
  const TrackingEvaluation clean = evaluateTracks(straight, truth, camera, {0, 0, 1}, {0, 0, 1}, {}, s);
  CHECK(clean.identity_swaps == 0);
  CHECK(clean.fraction_found == Approx(1.0));
}

TEST_CASE("a track whose blob comes apart between its prediction ends instead of guessing", "[track][identity]") {
  // One marker standing still at (100, 100); then two detections 6 px either side.
  LinkSettings s;
  s.max_distance_px = 10.0;
  s.ambiguity_ratio = 0.6;
  Linker linker(s);
  auto at = [](double u) {
    Detection d;
    d.centroid = {u, 100.0};
    return d;
  };
  linker.add(0, 0.000, {at(100.0)});
  linker.add(1, 0.002, {at(100.2)});
  linker.add(2, 0.004, {at(94.0), at(106.4)});
  CHECK(linker.ambiguousEnds() == std::vector<int>{0});
  REQUIRE(linker.tracks().size() == 3);
  CHECK(linker.tracks()[0].points.size() == 2);  // not continued on either piece
  // Clearly nearer one piece: followed (ratio 2 / 8 < 0.6).
  Linker clear(s);
  clear.add(0, 0.000, {at(100.0)});
  clear.add(1, 0.002, {at(100.2)});
  clear.add(2, 0.004, {at(102.4), at(108.4)});
  CHECK(clear.ambiguousEnds().empty());
  CHECK(clear.tracks()[0].points.size() == 3);
  // Off by default (ratio 1): the nearer is taken whatever the runner-up.
  Linker off(LinkSettings{10.0});
  off.add(0, 0.000, {at(100.0)});
  off.add(1, 0.002, {at(100.2)});
  off.add(2, 0.004, {at(94.0), at(106.4)});
  CHECK(off.ambiguousEnds().empty());
  CHECK_THROWS_WITH([] { LinkSettings bad; bad.ambiguity_ratio = 0.0; bad.validate(); }(),
                    Catch::Contains("link.ambiguity_ratio"));
}
