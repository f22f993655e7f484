#include "marker_tracking.h"

#include <chrono>

namespace rocklab::experiments {

MarkerTracking::MarkerTracking(const geometry::Camera& camera, double onset, double measure_distance)
    : camera_(camera), onset_(onset), measure_distance_(measure_distance) {}

void MarkerTracking::setMarkers(double plane_y, double radius) {
  plane_y_ = plane_y;
  // Projected disc of the marker at the plane's depth along the optical axis.
  const geometry::Vec3 centre_on_plane(camera_.position().x(), plane_y, camera_.position().z());
  const double depth = std::abs(camera_.toCamera(centre_on_plane).z());
  const double r_px = 0.5 * (camera_.fx + camera_.fy) * radius / std::max(depth, 1e-9);
  detector_.expected_area_px = 3.14159265358979 * r_px * r_px;
}

void MarkerTracking::addFrame(std::uint64_t frame, double time, const cv::Mat& bgr) {
  const auto t0 = std::chrono::steady_clock::now();
  linker_.add(static_cast<int>(frame), time, track::detectMarkers(bgr, detector_));
  ++frames_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

MarkerTracking::Result MarkerTracking::finish() const {
  Result r;
  const auto t0 = std::chrono::steady_clock::now();
  r.tracks = linker_.tracks();
  for (const track::Track& t : r.tracks)
    r.velocities.push_back(track::trackVelocity(t, camera_, planePoint(), geometry::Vec3::UnitY(),
                                                -geometry::Vec3::UnitX(), measure_distance_, onset_, reference_time_));
  r.frames = frames_;
  r.seconds = seconds_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace rocklab::experiments
