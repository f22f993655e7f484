#include "../world_impl.h"


namespace rocklab::sim {

using detail::PairProps;

// Mechanical energy at t (stage 5, observed steps only): kinetic from the
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
      const double rsum = p.radius[i] + p.radius[j];
      double overlap = rsum - (p.position[j] - p.position[i]).norm();
      if (relax.active()) overlap -= relax.factor * relax.pair[k];
      const PairProps& props = ball_ball[static_cast<std::size_t>(p.material[i]) * nm +
                                         static_cast<std::size_t>(p.material[j])];
      e.elastic += detail::elasticEnergy<Law>(props, overlap, 2.0 * p.radius[i] * p.radius[j] / rsum,
                                              history.pair_shear[k]);
    }
    for (std::uint32_t c = nb.wall_offset[i]; c < nb.wall_offset[i + 1]; ++c) {
      if (!history.wall_touch[c]) continue;
      const std::uint32_t wk = nb.wall_index[c];
      detail::WallContact wc;
      if (!walls[wk].contact(model.walls[wk], p.position[i], p.radius[i], wc)) continue;
      const PairProps& props = ball_wall[static_cast<std::size_t>(p.material[i]) * nm +
                                         static_cast<std::size_t>(model.walls[wk].material)];
      const double overlap = wc.overlap - (relax.active() ? relax.factor * relax.wall[c] : 0.0);
      e.elastic += detail::elasticEnergy<Law>(props, overlap, p.radius[i], history.wall_shear[c]);
    }
  }
  return e;
}

Energy World::Impl::energyAny(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const {
  Energy e = model.contact.law == ContactLaw::Linear ? energy<detail::LinearLaw>(v, w)
                                                     : energy<detail::HertzMindlinLaw>(v, w);
  if (!contributions.empty()) {
    const ForceInput in = forceInput();
    for (const auto& contribution : contributions) e.potential_other += contribution->potentialEnergy(in);
  }
  return e;
}

}  // namespace rocklab::sim
