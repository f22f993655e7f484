#pragma once
// The [experiment] settings of every driver type (reference: experiments.md
// §a drop, §b heap, §c chute, §d zoned chute), read by the drivers' settings
// readers (drivers/registry.h) at scene load time. Private to the library.
#include <cstdint>
#include <string>
#include <vector>

namespace rocklab::experiments {

/// What an [experiment] table asks the run to do besides stepping: phases
/// (deposit, tilt, open the gate), measurements and the end condition. One
/// struct for all types; each type reads the keys it needs (reference:
/// experiments.md §a drop, §b heap, §c chute, §d zoned chute).
struct ExperimentSettings {
  // Settling (heap; chute deposition): settled when no body is faster than
  // settle_speed, checked every check_interval, not before settle_min_time.
  double settle_speed = 0.02;      // m/s
  double settle_min_time = 0.1;    // s
  double settle_max_time = 3.0;    // s; a deposit still moving then is reported, not hidden
  double check_interval = 0.002;   // s; also the marker sampling interval (the lab filmed at 500 fps)
  // Heap.
  double base_z = 0.0;             // m, height of the table
  double bin_width = 0.01;         // m, silhouette bin of the angle measurement
  // Chute (frame: outlet at x = 0, feed end at x = length, base z = 0, camera wall y = 0).
  double length = 0.6;                 // m
  double inclination_deg = 30.0;       // deg, test inclination of the base
  double deposit_inclination_deg = 0.0;  // deg, gravity tilt while depositing (zoned chute: 45)
  // How the tilt enters (experiments.md §c [I]): true = gravity rotated by the
  // angle, |g| kept; false = the study's "additional component" g tan(angle)
  // along the base with the normal component kept at g.
  bool rotate_gravity = true;
  std::string gate_wall = "gate";      // wall removed to release the flow
  std::vector<std::string> temporary_walls;  // walls removed after deposition (zone separators)
  std::string top_wall;                // wall added after deposition; bodies cut by it are removed
  std::uint64_t tilt_steps = 5000;     // steps at the test inclination with the gate closed
  std::vector<double> marker_columns;  // m from the outlet, column 1 first
  std::vector<double> marker_heights;  // m above the base, the same in every column; or...
  std::vector<double> marker_height_fractions;  // ...fractions of the local channel height (top plate, else bed)
  double marker_y = 0.0;               // m, distance of the marker centres from the camera wall; 0 = one radius
  double measure_distance = 0.1;       // m of travel over which a marker's mean velocity is taken
  double remove_beyond = 0.1;          // m past the outlet where discharged bodies are deleted
  double jam_time = 1.0;               // s without any discharge (bodies left) = jammed
  std::string track_camera;            // camera whose frames are tracked ("" = the first camera, if any)
  bool track = true;                   // track the markers in that camera's frames
  int calibration_photos = 11;         // heap, chute: checkerboard photos the camera is calibrated from
                                       // (3-11) before images are measured; 0 = the renderer's exact camera
};

}  // namespace rocklab::experiments
