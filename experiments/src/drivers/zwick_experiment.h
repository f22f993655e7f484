#pragma once
// The Zwick crushing test (experiments.md §e, §f.2): its settings, reader and factory.
#include <memory>
#include <string>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"

namespace rocklab::experiments {

/// [experiment] keys of type "zwick".
struct ZwickSettings final : ExperimentSettings {
  std::string bottom_platen = "bottom";  // plane walls of the scene, facing each other
  std::string top_platen = "top";
  double platen_speed =
      0.008;                  // m/s, the top platen's closing speed (Table 5.2; the lab: 1 mm/min)
  bool settle_first = false;  // let the specimen settle on the bottom platen under gravity first
  SettleSettings settle;
  double start_gap = 2e-4;  // m between the top platen and the specimen when loading starts
  // m of platen travel between samples while loading (0: every sample_interval s). By
  // travel, a platen-speed study samples every speed at the same points of the curve.
  double sample_travel = 0.0;
  double max_strain =
      0.3;  // -  loading ends when the platens closed by this fraction of the specimen
  // §e failure rule: failed once the pieces broken off the largest fragment exceed this
  // fraction of the specimen's volume; the failure load is the peak load up to then.
  double failure_volume_fraction = 1.0 / 3.0;
  double end_drop =
      0.5;  // -  after failure the test ends once the load fell below (1 - end_drop) x peak
  double fines_size =
      0.008;  // m, fragments of smaller equivalent diameter are fines (the lab's 8 mm sieve)
};

std::shared_ptr<ExperimentSettings> readZwickSettings(TableReader& table,
                                                      const SettingsContext& context);
std::unique_ptr<Experiment> makeZwickExperiment(const Scene& scene);

}  // namespace rocklab::experiments
