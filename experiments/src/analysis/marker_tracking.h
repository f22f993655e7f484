#pragma once
// Lab-style tracking of the red markers in one camera's raw frames: the
// tracker (rocklab_track) sees only the images and the camera calibration,
// never the simulation. Velocities are taken like the DEM truth: along the base
// (-x), from 2 mm of travel to measure_distance, on the plane of the marker
// centres (y = marker plane, one marker radius behind the camera-side wall).
#include <cstdint>
#include <limits>
#include <optional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/track/stitch.h"
#include "rocklab/track/tracker.h"
#include "rocklab/track/velocity.h"

namespace rocklab::experiments {

class MarkerTracking {
 public:
  /// `onset` and `measure_distance` (m): the same as the chute's truth uses.
  MarkerTracking(const geometry::Camera& camera, double onset, double measure_distance);
  /// Where the markers sit (y of their centres: against the camera-side wall) and
  /// their equivalent radius, as the lab knows its painted pebbles: gives the
  /// expected blob area (touching markers are split), the linking gate and the
  /// stitching gate.
  void setMarkers(double plane_y, double radius);
  /// Model-based marker positions (track/shape_fit.h): the markers are clumps of
  /// these balls (m, about the centre of mass; a shape each, when the markers have
  /// several: each track takes the one that fits it best) touching the camera-side
  /// wall (y = 0, the bed at y > 0); call after setMarkers.
  void useShapeFit(const std::vector<std::vector<geometry::Sphere>>& shapes);
  /// The camera the tracker works with (e.g. the one recovered by calibration);
  /// call before setMarkers.
  void setCamera(const geometry::Camera& camera) { camera_ = camera; }
  /// Travel counts from each marker's position at this time (s; the gate opening),
  /// interpolated between frames; before it is set, from a track's first frame.
  void setReferenceTime(double time) { reference_time_ = time; }
  void addFrame(std::uint64_t frame, double time, const cv::Mat& bgr);

  struct Result {
    std::vector<track::Track> tracks;               // stitched
    std::vector<track::MarkerVelocity> velocities;  // one per track
    // With the shape fit, for comparison: the same tracks' velocities at other
    // depths (the fitted depth per frame, or the fitted pixels on the plane of the
    // marker centres), one per track each.
    std::vector<std::pair<std::string, std::vector<track::MarkerVelocity>>> depth_variants;
    bool shape_fit = false;
    std::size_t shapes = 0;  // marker shapes the fit chose among
    track::Tracker::ShapeFitCounts shape_fit_counts;
    std::vector<track::StitchJoin> joins;
    std::vector<int> unresolved;                    // track ids (before stitching) left apart
    std::vector<std::pair<int, double>> frames;     // (frame, time s) of every tracked frame
    double seconds = 0.0;  // wall time of detection, linking and stitching
  };
  Result finish() const;
  const geometry::Camera& camera() const { return camera_; }
  geometry::Vec3 planePoint() const { return {0.0, plane_y_, 0.0}; }
  double markerRadiusPx() const { return marker_radius_px_; }
  const track::TrackerSettings& settings() const { return tracker_->settings(); }

 private:
  geometry::Camera camera_;
  double onset_, measure_distance_;
  double plane_y_ = 0.0, marker_radius_px_ = 0.0;
  double reference_time_ = std::numeric_limits<double>::quiet_NaN();
  std::unique_ptr<track::Tracker> tracker_;
  std::optional<track::MarkerModel> shape_model_;  // with the shape fit
  std::size_t shape_count_ = 0;                     // marker shapes fitted
  std::vector<std::pair<int, double>> frames_;
  double seconds_ = 0.0;
};

}  // namespace rocklab::experiments
