#pragma once
// The product photograph (issue 21, "product size from images"): particles settle
// on a tray, a camera above photographs them, and the image-based size
// distribution (track/particle_sizing.h) is set beside the exact one: what a plant
// or lab that sizes its product from photographs would get, and how far off it is.
#include <memory>
#include <vector>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"
#include "rocklab/track/particle_sizing.h"

namespace rocklab::experiments {

/// [experiment] keys of type "product_photo".
struct ProductPhotoSettings final : ExperimentSettings {
  SettleSettings settle;
  double surface_z = 0.0;  // m, height of the tray the particles lie on
  std::vector<double> sieves_mm{4, 5.6, 8, 11.2, 16, 22.4, 31.5};
  track::SizingSettings sizing;
};

std::shared_ptr<ExperimentSettings> readProductPhotoSettings(TableReader& table, const SettingsContext& context);
std::unique_ptr<Experiment> makeProductPhotoExperiment(const Scene& scene);

}  // namespace rocklab::experiments
