#pragma once
// The drop test (experiments.md §a): its settings, reader and factory.
#include <memory>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"

namespace rocklab::experiments {

/// The drop test has no keys of its own.
struct DropSettings final : ExperimentSettings {};

std::shared_ptr<ExperimentSettings> readDropSettings(TableReader& table,
                                                     const SettingsContext& context);
std::unique_ptr<Experiment> makeDropExperiment(const Scene& scene);

}  // namespace rocklab::experiments
