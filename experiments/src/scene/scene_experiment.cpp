// Scene reader: [experiment], its type and the keys its driver reads.
#include "drivers/registry.h"
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

/// The [experiment] table: its type, and its keys read and checked by that
/// type's driver; nothing for a plain run.
void readExperiment(TableReader& root, Scene& scene) {
  auto t = root.table("experiment");
  if (!t) return;
  std::vector<std::string> types;
  for (const ExperimentDriver& d : experimentDrivers()) types.push_back(d.type);
  scene.experiment_type = t->requiredString("type", types);
  // The key was check_interval, the name [watchdog] gives a count of steps: a
  // scene still using it is told the new name rather than "unknown key".
  if (t->has("check_interval"))
    t->fail("check_interval", "renamed to experiment.sample_interval (seconds)");
  const double sample_interval =
      t->number("sample_interval", ExperimentSettings{}.sample_interval, Range::positive());
  // The driver reads and checks the keys of its type into its settings
  // (drivers/registry.cpp); they are documented as [experiment] type = "TYPE".
  t->setDocTable("experiment." + scene.experiment_type);
  auto settings = findExperimentDriver(scene.experiment_type)
                      ->read_settings(*t, SettingsContext{scene.model, scene.cameras});
  settings->sample_interval = sample_interval;
  t->finish();
  scene.experiment = std::move(settings);
}

}  // namespace rocklab::experiments::detail
