#pragma once
// The heap test (experiments.md §b): its settings, reader and factory.
#include <memory>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"

namespace rocklab::experiments {

/// [experiment] keys of type "heap".
struct HeapSettings final : ExperimentSettings {
  SettleSettings settle;
  int calibration_photos = 11;  // of the camera that takes the side photograph
  double base_z = 0.0;          // m, height of the table
  double bin_width = 0.01;      // m, silhouette bin of the angle measurement
};

std::shared_ptr<ExperimentSettings> readHeapSettings(TableReader& table,
                                                     const SettingsContext& context);
std::unique_ptr<Experiment> makeHeapExperiment(const Scene& scene);

}  // namespace rocklab::experiments
