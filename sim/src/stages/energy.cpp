#include "../world_impl.h"

namespace rocklab::sim {

// Mechanical energy at t (stage 6, observed steps only): kinetic from the
// synchronised velocities, gravity, the contact springs, and what the force
// contributions store.

template <class Law>
Energy World::Impl::energy(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const {
  Energy e;
  const ClumpState& cl = p.clumps;
  for (std::size_t c = 0; c < cl.size(); ++c) {
    e.kinetic_translational += 0.5 * cl.mass[c] * obs.clump_velocity[c].squaredNorm();
    const Vec3 body_w = cl.orientation[c].conjugate() * obs.clump_omega[c];
    e.kinetic_rotational += 0.5 * body_w.dot(body_w.cwiseProduct(cl.inertia[c]));
    e.potential_gravity -= cl.mass[c] * gravity.dot(cl.position[c]);
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!isMember(i)) {
      e.kinetic_translational += 0.5 * p.mass[i] * v[i].squaredNorm();
      e.kinetic_rotational += 0.5 / p.inv_inertia[i] * w[i].squaredNorm();
      e.potential_gravity -= p.mass[i] * gravity.dot(p.position[i]);
    }
    for (std::uint32_t k = nb.pairs.row_offset[i]; k < nb.pairs.row_offset[i + 1]; ++k) {
      if (!history.pair_touch[k]) continue;
      const std::uint32_t j = nb.pairs.partner[k];
      ContactPoint touch;
      if (!ballBallTouch(p.position[i], p.position[j], p.radius[i], p.radius[j], touch)) continue;
      e.elastic += detail::elasticEnergy<Law>(pairProps(i, j), pairOverlap(touch, k),
                                              effectiveRadius(p.radius[i], p.radius[j]), history.pair_shear[k]);
    }
    forEachWallTouch(walls, i, [&](std::uint32_t c, std::uint32_t wk, const ContactPoint* touch) {
      if (!history.wall_touch[c] || !touch) return;
      e.elastic += detail::elasticEnergy<Law>(wallProps(i, wk), wallOverlap(*touch, c), p.radius[i],
                                              history.wall_shear[c]);
    });
  }
  // Contacts of contact bonds that broke in this step: not yet in the pair list.
  for (const PairHistory& h : bonds.handover) {
    ContactPoint touch;
    if (!ballBallTouch(p.position[h.i], p.position[h.j], p.radius[h.i], p.radius[h.j], touch)) continue;
    e.elastic += detail::elasticEnergy<Law>(pairProps(h.i, h.j), touch.overlap,
                                            effectiveRadius(p.radius[h.i], p.radius[h.j]), h.shear);
  }
  return e;
}

Energy World::Impl::energyAny(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const {
  Energy e = model.contact.law == ContactLaw::Linear ? energy<detail::LinearLaw>(v, w)
                                                     : energy<detail::HertzMindlinLaw>(v, w);
  if (bonds.any()) e.bond = bondEnergy();
  if (!contributions.empty()) {
    const ForceInput in = forceInput();
    for (const auto& contribution : contributions) e.potential_other += contribution->potentialEnergy(in);
  }
  return e;
}

}  // namespace rocklab::sim
