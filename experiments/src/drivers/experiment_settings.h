#pragma once
// What the [experiment] settings of every driver type share: the base struct
// each driver's own settings derive from (drop_experiment.h, heap_experiment.h,
// chute_experiment.h), the context their readers may look at, and the readers
// of the keys several types have. Private to the library.
#include <memory>
#include <vector>

#include "rocklab/experiments/scene.h"
#include "scene/toml_reader.h"

namespace rocklab::experiments {

using detail::Range;
using detail::TableReader;

/// The keys of [experiment] every type has (read by the scene reader).
struct ExperimentSettings {
  virtual ~ExperimentSettings() = default;
  double sample_interval = 0.002;  // s between the driver's samples (the lab filmed at 500 fps)
  // The key of [experiment] whose value makes a run useless without its checkpoint
  // (a chute's stop_after); "" = none. The scene reader then asks for output.checkpoint.
  std::string needs_checkpoint;
};

/// The settings of `scene`'s experiment as its driver's type (the registry pairs
/// each type's reader with its factory, so a wrong type is a programming error).
template <class Settings>
const Settings& settingsOf(const Scene& scene) {
  return dynamic_cast<const Settings&>(*scene.experiment);
}

/// What a driver's settings reader may look at besides its table.
struct SettingsContext {
  const sim::Model& model;                     // walls by name
  const std::vector<CameraSettings>& cameras;  // cameras by name
};

/// Settling (heap; chute deposition; the coming Zwick and crusher feeds): settled
/// when no body is faster than `speed`, looked at every sample_interval, not before
/// min_time (drivers/settle.h).
struct SettleSettings {
  double speed = 0.02;    // m/s
  double min_time = 0.1;  // s
  double max_time = 3.0;  // s; a deposit still moving then is reported, not hidden
};

/// settle_speed, settle_min_time, settle_max_time.
void readSettleSettings(TableReader& table, SettleSettings& settle);

/// calibration_photos (heap, chute): checkerboard photos the camera is calibrated
/// from (3-11) before images are measured; 0 = the renderer's exact camera.
int readCalibrationPhotos(TableReader& table, int fallback);

}  // namespace rocklab::experiments
