#pragma once
// The inclined chute and the zoned chute (experiments.md §c, §d): their
// settings, reader and factory.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"

namespace rocklab::experiments {

/// [experiment] keys of type "chute". Chute frame: outlet at x = 0, feed end at
/// x = length, base z = 0, camera wall y = 0.
struct ChuteSettings final : ExperimentSettings {
  SettleSettings settle;                 // the deposit
  int calibration_photos = 11;           // of the tracking camera
  double length = 0.6;                   // m
  double inclination_deg = 30.0;         // deg, test inclination of the base
  double deposit_inclination_deg = 0.0;  // deg, gravity tilt while depositing (zoned chute: 45)
  // How the tilt enters (experiments.md §c [I]): true = gravity rotated by the
  // angle, |g| kept; false = the study's "additional component" g tan(angle)
  // along the base with the normal component kept at g.
  bool rotate_gravity = true;
  std::string gate_wall = "gate";            // wall removed to release the flow
  std::vector<std::string> temporary_walls;  // walls removed after deposition (zone separators)
  std::string top_wall;                // wall added after deposition; bodies cut by it are removed
  // Whose speed ends the deposit (with a top_wall): "kept" = the balls the top plate
  // keeps (those it cuts are deleted, so their rolling does not hold the deposit);
  // "all" = every ball.
  std::string settle_scope = "kept";
  // "deposit": the run ends where the deposit is over, before the top plate is
  // placed, so that one deposit (its checkpoint) serves every plate of a study
  // (`rocklab sweep CHECKPOINT --vary walls.top...`); "none": the whole test.
  std::string stop_after = "none";
  std::uint64_t tilt_steps = 5000;     // steps at the test inclination with the gate closed
  std::vector<double> marker_columns;  // m from the outlet, column 1 first
  std::vector<double> marker_heights;  // m above the base, the same in every column; or...
  std::vector<double>
      marker_height_fractions;  // ...fractions of the local channel height (top plate, else bed)
  double marker_y = 0.0;  // m, distance of the marker centres from the camera wall; 0 = one radius
  double measure_distance = 0.1;  // m of travel over which a marker's mean velocity is taken
  double remove_beyond = 0.1;     // m past the outlet where discharged bodies are deleted
  double jam_time = 1.0;          // s without any discharge (bodies left) = jammed
  std::string track_camera;       // camera whose frames are tracked (default the first; "" = none)
  bool track = true;              // track the markers in that camera's frames
  // A marker's image position: "shape" = the projected outline of its clump fitted
  // to the blob's edges (track/shape_fit.h), "centroid" = the blob's redness-weighted centroid.
  std::string track_position = "shape";
};

std::shared_ptr<ExperimentSettings> readChuteSettings(TableReader& table,
                                                      const SettingsContext& context);
std::unique_ptr<Experiment> makeChuteExperiment(const Scene& scene);

}  // namespace rocklab::experiments
