// Scene reader: the engine's settings, [gravity], [timestep], [neighbours],
// [watchdog] (check_interval in steps) and [relaxation].
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

/// [gravity]: the vector and its schedule of changes.
void readGravity(TableReader& root, sim::Model& model) {
  if (auto t = root.table("gravity")) {
    model.gravity = t->vec3("vector", model.gravity);
    for (TableReader c : t->tableArray("change")) {
      sim::GravityChange g;
      g.time = c.requiredNumber("time", Range::nonNegative());
      g.vector = c.requiredVec3("vector");
      if (!model.gravity_changes.empty() && g.time <= model.gravity_changes.back().time)
        c.fail("time", "gravity changes must be in increasing time order");
      model.gravity_changes.push_back(g);
      c.finish();
    }
    t->finish();
  }
}

/// [timestep], [neighbours], [watchdog], [relaxation]: how the engine steps.
void readEngine(TableReader& root, sim::Model& model) {
  if (auto t = root.table("timestep")) {
    model.timestep.safety_factor =
        t->number("safety_factor", model.timestep.safety_factor, {0.0, 1.0, true, false});
    model.timestep.dt = t->number("dt", 0.0, Range::nonNegative());
    model.timestep.impact_velocity =
        t->number("impact_velocity", model.timestep.impact_velocity, Range::positive());
    model.timestep.allow_unsafe = t->boolean("allow_unsafe", false);
    t->finish();
  }
  if (auto t = root.table("neighbours")) {
    model.skin = t->number("skin", 0.0, Range::nonNegative());
    model.max_grid_levels =
        static_cast<int>(t->integer("max_levels", model.max_grid_levels, Range::closed(1, 8)));
    t->finish();
  }
  if (auto t = root.table("watchdog")) {
    model.watchdog.max_overlap_fraction = t->number(
        "max_overlap_fraction", model.watchdog.max_overlap_fraction, {0.0, 2.0, true, false});
    model.watchdog.max_energy_growth =
        t->number("max_energy_growth", model.watchdog.max_energy_growth, Range::nonNegative());
    model.watchdog.check_interval = static_cast<int>(
        t->integer("check_interval", model.watchdog.check_interval, Range::closed(1, 1e9)));
    model.watchdog.network_iterations = static_cast<int>(t->integer(
        "network_iterations", model.watchdog.network_iterations, Range::closed(0, 1000)));
    model.watchdog.network_interval = static_cast<int>(
        t->integer("network_interval", model.watchdog.network_interval, Range::closed(1, 1e9)));
    t->finish();
  }
  if (auto t = root.table("relaxation")) {
    model.relaxation.steps = static_cast<int>(t->integer("steps", 0, Range::closed(0, 1e9)));
    t->finish();
  }
}

}  // namespace rocklab::experiments::detail
