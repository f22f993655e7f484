#pragma once
// The cone crusher's run (experiments.md §g.4): the feed falls from the feed bin
// when the stop wall goes (both walls and the mantle motion are scene data, from
// [crusher]); this driver detects the discharge below the chamber: a sphere whose
// centre falls below discharge_height is product, counted with its size and
// removed. The run ends when no ball is left (the chamber is empty) or at end_time.
// With [experiment.breakage] balls break (§g.6, drivers/crusher_breakage.h). A
// bonded feed (§g.7: agglomerates) breaks by its bonds: a fragment (balls joined by
// intact bonds) is product when its centre of mass is below discharge_height, sized
// by Eq 6-15.
#include <memory>

#include "drivers/crusher_breakage.h"
#include "drivers/crusher_whiten.h"
#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"

namespace rocklab::experiments {

struct CrusherRunSettings final : ExperimentSettings {
  double discharge_height = -0.03;  // m: a ball whose centre is lower is product (below the concave's lip)
  // Sieve apertures of the product's cumulative passing (mass), mm.
  std::vector<double> sieves_mm{2, 4, 5.6, 8, 11.2, 14, 16, 20, 22.4, 25, 28, 31.5};
  // §g.7's bonded feed: the bonds' strengths times this until the feed bin's stop
  // wall goes (crusher.release_time), so nothing breaks while the feed settles.
  double settle_bond_factor = 1.0;
  BreakageSettings breakage;  // [experiment.breakage]; off without the table
  WhitenSettings whiten;      // whiten_k1_mm, whiten_k2_mm, whiten_exponent
};

std::shared_ptr<ExperimentSettings> readCrusherRunSettings(TableReader& table, const SettingsContext& context);
std::unique_ptr<Experiment> makeCrusherRunExperiment(const Scene& scene);

}  // namespace rocklab::experiments
