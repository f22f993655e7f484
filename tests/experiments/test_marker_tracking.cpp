// The chute's marker tracking (analysis/marker_tracking.h) on drawn frames: two
// markers that overlap in the first frame under sensor noise (issue 25).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "analysis/marker_tracking.h"
#include "track/track_scenes.h"

using namespace rocklab;
using namespace rocklab::track::test;

namespace {

constexpr double kMarkerRadius = 0.008;  // m, equivalent radius of a marker
constexpr double kPlaneY = kMarkerRadius;  // m, marker centres one radius behind the camera wall
constexpr double kStill = 0.01;            // s before the markers move
constexpr double kMeasure = 0.05;          // m of travel measured

struct Marker {
  Vec3 start;
  double speed;  // m/s along −x
  Vec3 at(double t) const { return start - Vec3::UnitX() * speed * std::max(0.0, t - kStill); }
};

// Grey frame with sensor noise of 15 grey levels (the study's worst), each marker
// drawn at its projected centre as a disc of kShown of its equivalent sphere's
// radius (a marker partly hidden among pebbles shows less than its equivalent disc).
constexpr double kShown = 0.85;
cv::Mat frameAt(const geometry::Camera& camera, const std::vector<Marker>& markers, double t, int k,
               double shown = kShown) {
  cv::Mat frame = greyFrame({camera.width, camera.height}, 15.0, 1000 + static_cast<std::uint64_t>(k));
  for (const Marker& m : markers) {
    const Vec3 c = m.at(t);
    const geometry::Vec2 px = camera.project(c);
    const double r_px = shown * camera.fx * kMarkerRadius / camera.toCamera(c).z();
    drawDisc(frame, {px.x(), px.y()}, r_px);
  }
  return frame;
}

geometry::Camera chuteCamera() {
  geometry::Camera camera = geometry::Camera::withFieldOfView(640, 480, 60.0);
  camera.frameRate = kFrameRate;
  camera.lookAt(Vec3(0.0, -0.35, 0.03), Vec3(0.0, 0.15, 0.03), Vec3::UnitZ());
  return camera;
}

}  // namespace

TEST_CASE("two markers merged in the first noisy frame start two tracks with their own velocities",
          "[experiments][tracking]") {
  const geometry::Camera camera = chuteCamera();
  // One above the other, their shown discs overlapping by 0.3 of their radius: one
  // blob of about 1.5 marker areas (fill ~0.6), more than one marker covers but under
  // the former size rule's 1.8 (issue 25: 1.75, fill 0.40), so it was one detection
  // and one track at the pair's middle; the upper marker is faster and pulls away.
  const std::vector<Marker> markers{{Vec3(0.04, kPlaneY, 0.02), 0.25},
                                    {Vec3(0.04, kPlaneY, 0.02 + 1.7 * kShown * kMarkerRadius), 0.35}};
  experiments::MarkerTracking tracking(camera, 0.002, kMeasure);
  tracking.setMarkers(kPlaneY, kMarkerRadius);
  tracking.setReferenceTime(0.0);
  const double r_px = tracking.markerRadiusPx();
  const int frames = static_cast<int>(std::ceil((kStill + kMeasure / 0.25 + 0.02) * kFrameRate));
  for (int k = 0; k < frames; ++k) tracking.addFrame(static_cast<std::uint64_t>(k), k / kFrameRate,
                                                     frameAt(camera, markers, k / kFrameRate, k));
  const experiments::MarkerTracking::Result result = tracking.finish();
  REQUIRE(result.velocities.size() == result.tracks.size());
  CHECK(result.tracks.size() == 2);  // one track a marker from the first frame, never one on both

  for (std::size_t m = 0; m < markers.size(); ++m) {
    // The track that starts nearest the marker's first pixel (as the chute's report pairs them).
    const geometry::Vec2 first = camera.project(markers[m].at(0.0));
    std::size_t best = 0;
    auto miss = [&](std::size_t j) { return cv::norm(result.tracks[j].points.front().pixel - cv::Point2d(first.x(), first.y())); };
    for (std::size_t j = 1; j < result.tracks.size(); ++j)
      if (miss(j) < miss(best)) best = j;
    const track::Track& t = result.tracks[best];
    INFO("marker " << m << ": track " << t.id << " of " << result.tracks.size() << ", starts " << miss(best)
                    << " px from it at frame " << t.points.front().frame);
    CHECK(t.points.front().frame == 0);
    CHECK(miss(best) < 0.15 * r_px);  // its own piece of the merged blob (before: the blob's middle, 0.7 r_px off)
    // It follows this marker, never the other.
    double worst = 0;
    for (const track::TrackPoint& p : t.points) {
      const geometry::Vec2 truth = camera.project(markers[m].at(p.time));
      worst = std::max(worst, cv::norm(p.pixel - cv::Point2d(truth.x(), truth.y())));
    }
    CHECK(worst < 0.15 * r_px);
    const track::MarkerVelocity& v = result.velocities[best];
    CHECK_FALSE(v.merged);
    REQUIRE(v.complete);
    CHECK(v.velocity == Approx(markers[m].speed).epsilon(0.01));
  }
}

TEST_CASE("a red speck for one frame ahead of two touching markers starts no track that cuts them apart",
          "[experiments][tracking]") {
  // Two touching markers, one ahead of the other, move together: one blob, cut at
  // their two tracks' predictions. For one frame a speck of red (6 % of a marker's
  // disc) shows 4 px ahead of the leading marker. At sensor noise 15 such a speck
  // where two markers met started a track (issue 25), whose prediction stood still
  // until the leading marker ran over it and was then a third seed in the pair's
  // blob: the marker was cut in two and its track lost. A blob under a tenth of a
  // marker's disc is no marker (MarkerTracking: the detector's min_area_px). Without
  // that bound the speck's track cut a third piece off the pair five frames later,
  // and that piece was tracked beside the marker to the end.
  const geometry::Camera camera = chuteCamera();
  constexpr double kShownPair = 0.9;  // two shown discs cover 1.6 marker discs: one blob to cut
  const double z = 0.03, speed = 0.3;
  const std::vector<Marker> markers{{Vec3(0.04, kPlaneY, z), speed},
                                    {Vec3(0.04 + 2 * kShownPair * kMarkerRadius, kPlaneY, z), speed}};
  experiments::MarkerTracking tracking(camera, 0.002, kMeasure);
  tracking.setMarkers(kPlaneY, kMarkerRadius);
  tracking.setReferenceTime(0.0);
  const double r_px = tracking.markerRadiusPx();
  const int speck_frame = 10;  // moving since frame 5
  const int frames = static_cast<int>(std::ceil((kStill + kMeasure / speed + 0.02) * kFrameRate));
  for (int k = 0; k < frames; ++k) {
    const double t = k / kFrameRate;
    cv::Mat frame = frameAt(camera, markers, t, k, kShownPair);
    if (k == speck_frame) {
      const geometry::Vec2 lead = camera.project(markers[0].at(t));
      const double shown_px = kShownPair * r_px, speck_px = 0.25 * r_px;
      drawDisc(frame, {lead.x() - shown_px - 4.0 - speck_px, lead.y()}, speck_px);  // image u grows with x
    }
    tracking.addFrame(static_cast<std::uint64_t>(k), t, frame);
  }
  const experiments::MarkerTracking::Result result = tracking.finish();
  CHECK(result.tracks.size() == 2);
  CHECK(result.unresolved.empty());
  REQUIRE(result.velocities.size() == result.tracks.size());
  for (const track::MarkerVelocity& v : result.velocities) {
    INFO("track " << v.track_id);
    REQUIRE(v.complete);
    CHECK(v.velocity == Approx(speed).epsilon(0.01));
  }
}
