#include "analysis/tracking_report.h"

#include <algorithm>
#include <string>

#include "analysis/plot.h"
#include "rocklab/track/export.h"

namespace rocklab::experiments {

namespace {

// Tracks with a point on a merged detection (two or more markers in one blob), each
// with whether its velocity was withheld for it (the merged point was measured).
nlohmann::json mergedTracks(const MarkerTracking::Result& result) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < result.tracks.size(); ++k) {
    const track::Track& t = result.tracks[k];
    const auto points = std::count_if(t.points.begin(), t.points.end(), [](const track::TrackPoint& p) { return p.merged; });
    if (points == 0) continue;
    const bool withheld = k < result.velocities.size() && result.velocities[k].merged;
    out.push_back({{"track", t.id}, {"merged_points", points}, {"velocity_withheld", withheld}});
  }
  return out;
}

}  // namespace

void MarkerTruth::add(std::size_t marker, double time, const geometry::Vec3& centre) {
  samples_.at(marker).emplace_back(time, centre);
}

std::vector<track::TruthMarker> MarkerTruth::atFrames(const std::vector<std::pair<int, double>>& frames,
                                                      const geometry::Camera& true_camera) const {
  std::vector<track::TruthMarker> out(samples_.size());
  for (std::size_t m = 0; m < samples_.size(); ++m) {
    out[m].id = static_cast<int>(m);
    const auto& s = samples_[m];
    std::size_t k = 1;
    for (const auto& [frame, time] : frames) {
      if (s.empty() || time < s.front().first || time > s.back().first) continue;
      while (k < s.size() && s[k].first < time) ++k;
      geometry::Vec3 centre = s.front().second;
      if (k < s.size()) {
        const double span = s[k].first - s[k - 1].first;
        const double f = span > 0 ? (time - s[k - 1].first) / span : 0.0;
        centre = s[k - 1].second + f * (s[k].second - s[k - 1].second);
      }
      if (!(true_camera.toCamera(centre).z() > 0)) continue;  // behind the camera: not in view
      const geometry::Vec2 px = true_camera.project(centre);
      out[m].points.push_back({frame, {px.x(), px.y()}, centre});
    }
  }
  return out;
}

nlohmann::json trackingErrorReport(const MarkerTracking& tracking, const MarkerTracking::Result& result,
                                   const MarkerTruth& truth, const geometry::Camera& true_camera,
                                   nlohmann::json& markers, const std::filesystem::path& png,
                                   const std::filesystem::path& pairs_csv) {
  track::EvaluationSettings settings;
  settings.match_distance_px = tracking.markerRadiusPx();
  settings.image_size = {true_camera.width, true_camera.height};
  const std::vector<track::TruthMarker> truth_at_frames = truth.atFrames(result.frames, true_camera);
  const track::TrackingEvaluation e = track::evaluateTracks(
      result.tracks, truth_at_frames, tracking.camera(), tracking.planePoint(), geometry::Vec3::UnitY(),
      {{"x", geometry::Vec3::UnitX()}, {"z", geometry::Vec3::UnitZ()}}, settings);
  track::writePairedCsv(pairs_csv, e, truth_at_frames);

  nlohmann::json pixel, world;
  for (const track::AxisError& a : e.pixel_error) pixel[a.axis] = {{"bias_px", a.bias}, {"rms_px", a.rms}};
  for (const track::AxisError& a : e.world_error) world[a.axis] = {{"bias_m", a.bias}, {"rms_m", a.rms}};
  std::vector<double> bin_centres;
  const int bins = settings.subpixel_bins;
  for (int k = 0; k < bins; ++k) bin_centres.push_back(-0.5 + (k + 0.5) / bins);
  nlohmann::json per_marker = nlohmann::json::array();
  for (std::size_t m = 0; m < e.markers.size() && m < markers.size(); ++m) {
    markers[m]["fraction_found"] = e.markers[m].fraction_found;
    markers[m]["track_ids_in_frames"] = e.markers[m].track_ids;
    markers[m]["pixel_rms_px"] = e.markers[m].rms_px;
    per_marker.push_back(e.markers[m].fraction_found);
  }
  nlohmann::json joins = nlohmann::json::array();
  for (const track::StitchJoin& j : result.joins)
    joins.push_back({{"from_track", j.from_id}, {"to_track", j.to_id}, {"gap_frames", j.gap_frames}, {"miss_px", j.miss_px}});
  const track::TrackerSettings& s = tracking.settings();
  nlohmann::json report = {
      {"method",
       "each frame, the truth markers in view (centres projected by the renderer's camera) and the track "
       "points are paired by least total squared distance, at most match_distance_px apart; errors are "
       "tracked minus truth (world: the tracked centre, fitted or the pixel on the marker plane, minus the true centre)"},
      {"match_distance_px", settings.match_distance_px},
      {"pairs", e.pairs},
      {"pixel_error", pixel},
      {"world_error", world},
      {"subpixel_histogram", {{"bin_centres_px", bin_centres}, {"u", e.subpixel_u}, {"v", e.subpixel_v}}},
      {"fraction_found", e.fraction_found},
      {"fraction_found_per_marker", per_marker},
      {"identity_swaps", e.identity_swaps},
      {"track_changes", e.track_changes},
      {"stitch_gate", {{"max_gap_frames", s.stitch.max_gap_frames},
                       {"max_distance_px", s.stitch.max_distance_px},
                       {"ambiguity_ratio", s.stitch.ambiguity_ratio}}},
      {"link_gate", {{"max_distance_px", s.link.max_distance_px}, {"max_missed_frames", s.link.max_missed_frames}}},
      {"stitched", joins},
      {"unresolved_tracks", result.unresolved},
      {"merged_tracks", mergedTracks(result)}};

  PlotSpec plot;
  plot.title = "pixel locking: " + std::to_string(e.pairs) + " tracked positions";
  plot.x_label = "tracked position - nearest pixel centre (px)";
  plot.y_label = "points per bin";
  std::vector<double> u(e.subpixel_u.begin(), e.subpixel_u.end()), v(e.subpixel_v.begin(), e.subpixel_v.end());
  plot.series = {PlotSeries{"u (across)", bin_centres, u, PlotSeries::Style::LinePoints},
                 PlotSeries{"v (down)", bin_centres, v, PlotSeries::Style::LinePoints}};
  plot.y_range = std::make_pair(0.0, 1.1 * std::max(*std::max_element(u.begin(), u.end()),
                                                     *std::max_element(v.begin(), v.end())) + 1.0);
  writePlot(plot, png);
  return report;
}

}  // namespace rocklab::experiments
