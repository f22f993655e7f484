#pragma once
// The experiment registry: from an [experiment] table's `type` to the driver
// that reads and checks its keys into its own settings struct (at scene load
// time, with file:line messages) and the factory that builds it. Adding an
// experiment: a driver file with its settings, reader and factory, and one line
// in registry.cpp.
#include <memory>
#include <string>
#include <vector>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"

namespace rocklab::experiments {

struct ExperimentDriver {
  const char* type;  // the `type` value of [experiment]
  /// Reads and validates this type's keys of [experiment] into its settings.
  std::shared_ptr<ExperimentSettings> (*read_settings)(TableReader& table,
                                                       const SettingsContext& context);
  /// Builds the driver from a scene whose settings this type's reader made.
  std::unique_ptr<Experiment> (*make)(const Scene& scene);
};

/// Every driver, in the order `type` lists them in messages.
const std::vector<ExperimentDriver>& experimentDrivers();
/// The driver of `type`, or null.
const ExperimentDriver* findExperimentDriver(const std::string& type);

}  // namespace rocklab::experiments
