#pragma once
// The tracking-error report of a filmed experiment: the tracker's tracks against
// the DEM truth of its markers, frame by frame (track/evaluate.h), as results.json
// `tracking.error_report` and tracking_error.png. Only the report reads the truth.
#include <cstddef>
#include <filesystem>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/marker_tracking.h"
#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/vec.h"
#include "rocklab/track/evaluate.h"

namespace rocklab::experiments {

/// Marker centres sampled by the experiment (time order per marker).
class MarkerTruth {
 public:
  explicit MarkerTruth(std::size_t markers = 0) : samples_(markers) {}
  void add(std::size_t marker, double time, const geometry::Vec3& centre);
  /// Each marker at the tracked frames within its samples (linear interpolation),
  /// projected by the renderer's camera; ids are the markers' indices.
  std::vector<track::TruthMarker> atFrames(const std::vector<std::pair<int, double>>& frames,
                                           const geometry::Camera& true_camera) const;

 private:
  std::vector<std::vector<std::pair<double, geometry::Vec3>>> samples_;
};

/// Evaluates the tracks (match distance: one marker radius in px; world axes x and
/// z, the plane of the film), writes `png` and every truth-track pair of every frame
/// to `pairs_csv` (track/export.h), and returns the JSON block; per-marker figures go
/// into `markers[k]` (fraction_found, track_ids_in_frames, pixel_rms_px).
nlohmann::json trackingErrorReport(const MarkerTracking& tracking, const MarkerTracking::Result& result,
                                   const MarkerTruth& truth, const geometry::Camera& true_camera,
                                   nlohmann::json& markers, const std::filesystem::path& png,
                                   const std::filesystem::path& pairs_csv);

}  // namespace rocklab::experiments
