#include "../world_impl.h"

namespace rocklab::sim {

// Stage 1, prepare.
// Reads: time, the model's gravity schedule and wall motions, the largest
// displacement since the last neighbour build.
// Writes: gravity, wall poses and activity (walls), nb.need_rebuild; drops the
// watchdog's energy reference when gravity turns or a wall comes or goes.

void World::Impl::prepareStage() {
  for (const GravityChange& g : model.gravity_changes) {
    if (g.time <= time && g.time > time - dt && gravity != g.vector) {
      gravity = g.vector;
      guard.energy_ref_valid = false;  // gravity did work on the system: new reference
    }
  }
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const bool was_active = walls[k].active;
    walls[k].update(model.walls[k], time);
    if (walls[k].active && !was_active) nb.need_rebuild = true;
    if (walls[k].active != was_active) guard.energy_ref_valid = false;
    if (walls[k].displacementSinceReference() > 0.5 * nb.skin) nb.need_rebuild = true;
  }
  if (nb.last_max_disp2 > 0.25 * nb.skin * nb.skin) nb.need_rebuild = true;
}

}  // namespace rocklab::sim
