#include "drivers/registry.h"

namespace rocklab::experiments {

const std::vector<ExperimentDriver>& experimentDrivers() {
  static const std::vector<ExperimentDriver> drivers = {
      {"drop", readDropSettings, makeDropExperiment},
      {"heap", readHeapSettings, makeHeapExperiment},
      {"chute", readChuteSettings, makeChuteExperiment},
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

void readSettleSettings(TableReader& t, ExperimentSettings& e) {
  const Range positive = Range::positive();
  e.settle_speed = t.number("settle_speed", e.settle_speed, positive);
  e.settle_min_time = t.number("settle_min_time", e.settle_min_time, Range::nonNegative());
  e.settle_max_time = t.number("settle_max_time", e.settle_max_time, positive);
  e.calibration_photos = static_cast<int>(t.integer("calibration_photos", e.calibration_photos, Range::closed(0, 11)));
  if (e.calibration_photos > 0 && e.calibration_photos < 3)
    t.fail("calibration_photos", "needs 0 (exact camera) or 3 to 11 photos (got " + std::to_string(e.calibration_photos) + ")");
}

}  // namespace rocklab::experiments
