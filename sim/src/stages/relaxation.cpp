#include "../world_impl.h"

namespace rocklab::sim {

/// Takes every touching contact's overlap as its relaxation offset (first step
/// of a world built with Model::relaxation.steps > 0).
void World::Impl::startRelaxation() {
  relax.pending = false;
  relax.start(nb.pairs.size(), nb.wall_index.size());
  bool any = false;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::uint32_t k = nb.pairs.row_offset[i]; k < nb.pairs.row_offset[i + 1]; ++k) {
      const std::uint32_t j = nb.pairs.partner[k];
      ContactPoint touch;
      if (ballBallTouch(p.position[i], p.position[j], p.radius[i], p.radius[j], touch) && touch.overlap > 0) {
        relax.pair[k] = touch.overlap;
        any = true;
      }
    }
    forEachWallTouch(walls, i, [&](std::uint32_t c, std::uint32_t, const ContactPoint* touch) {
      if (touch && touch->overlap > 0) {
        relax.wall[c] = touch->overlap;
        any = true;
      }
    });
  }
  if (!any) relax.stop();
}

/// Offset factor of this step; frees the offsets once the relaxation is over.
void World::Impl::updateRelaxation() {
  const auto n = static_cast<std::uint64_t>(std::max(0, model.relaxation.steps));
  if (step >= n) {
    relax.stop();
    guard.energy_ref_valid = false;  // the energy check starts afresh from the relaxed state
    return;
  }
  // Smoothstep: the offset starts and ends shrinking at zero rate, so the bodies
  // are not jerked into motion at the start nor left moving at the end (a linear
  // ramp leaves them with up to twice its rate). Peak rate 1.5 x offset / (n dt).
  const double x = static_cast<double>(step) / static_cast<double>(n);
  relax.factor = 1.0 - x * x * (3.0 - 2.0 * x);
}

}  // namespace rocklab::sim
