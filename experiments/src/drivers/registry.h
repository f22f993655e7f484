#pragma once
// The experiment registry: from an [experiment] table's `type` to the driver
// that reads and checks its keys (at scene load time, with file:line messages)
// and the factory that builds it. Adding an experiment: a driver file with its
// reader and factory, and one line in registry.cpp.
#include <memory>
#include <string>
#include <vector>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"
#include "scene/toml_reader.h"

namespace rocklab::experiments {

using detail::Range;
using detail::TableReader;

/// What a driver's settings reader may look at besides its table.
struct SettingsContext {
  const sim::Model& model;                     // walls by name
  const std::vector<CameraSettings>& cameras;  // cameras by name
};

struct ExperimentDriver {
  const char* type;  // the `type` value of [experiment]
  /// Reads and validates this type's keys of [experiment] into `settings`.
  void (*read_settings)(TableReader& table, const SettingsContext& context, ExperimentSettings& settings);
  std::unique_ptr<Experiment> (*make)(const Scene& scene);
};

/// Every driver, in the order `type` lists them in messages.
const std::vector<ExperimentDriver>& experimentDrivers();
/// The driver of `type`, or null.
const ExperimentDriver* findExperimentDriver(const std::string& type);

// The settings readers and factories (one driver file each).
void readDropSettings(TableReader& table, const SettingsContext& context, ExperimentSettings& settings);
void readHeapSettings(TableReader& table, const SettingsContext& context, ExperimentSettings& settings);
void readChuteSettings(TableReader& table, const SettingsContext& context, ExperimentSettings& settings);
std::unique_ptr<Experiment> makeDropExperiment(const Scene& scene);
std::unique_ptr<Experiment> makeHeapExperiment(const Scene& scene);
std::unique_ptr<Experiment> makeChuteExperiment(const Scene& scene);

/// The keys every settling experiment shares (heap; chute deposition; the
/// coming Zwick and crusher feeds): settle_speed, settle_min_time,
/// settle_max_time, and the camera calibration photos.
void readSettleSettings(TableReader& table, ExperimentSettings& settings);

}  // namespace rocklab::experiments
