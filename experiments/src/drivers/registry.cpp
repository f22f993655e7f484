#include "drivers/registry.h"

#include "drivers/chute_experiment.h"
#include "drivers/crusher_experiment.h"
#include "drivers/drop_experiment.h"
#include "drivers/heap_experiment.h"
#include "drivers/product_photo_experiment.h"
#include "drivers/zwick_experiment.h"

namespace rocklab::experiments {

const std::vector<ExperimentDriver>& experimentDrivers() {
  static const std::vector<ExperimentDriver> drivers = {
      {"drop", readDropSettings, makeDropExperiment},
      {"heap", readHeapSettings, makeHeapExperiment},
      {"chute", readChuteSettings, makeChuteExperiment},
      {"zwick", readZwickSettings, makeZwickExperiment},
      {"crusher", readCrusherRunSettings, makeCrusherRunExperiment},
      {"product_photo", readProductPhotoSettings, makeProductPhotoExperiment},
  };
  return drivers;
}

const ExperimentDriver* findExperimentDriver(const std::string& type) {
  for (const ExperimentDriver& d : experimentDrivers())
    if (type == d.type) return &d;
  return nullptr;
}

std::unique_ptr<Experiment> makeExperiment(const Scene& scene) {
  const ExperimentDriver* driver = findExperimentDriver(scene.experiment_type);
  return driver ? driver->make(scene) : nullptr;
}

}  // namespace rocklab::experiments
