#include "../world_impl.h"

namespace rocklab::sim {

// Stage 3, forces: the contact law at every pair and wall contact, gathered per
// ball; on fused steps (StepPlan::fused) with the kick and drift of stage 8.
// Reads: positions, velocities, spins (t - dt/2), radii, materials, nb, walls.
// Writes: scratch.acc_force/acc_torque (set outright), history (shear springs,
// touching flags), the watchdog's wall work, the step checks; on fused steps
// the integrated state as stage 8 would.
// The contact law, the pass and its caller are in this one unit so that
// evaluateTouchingPair and addWallForces inline into the pass.
//
// Each thread owns a contiguous range of balls [b, e). A pair (i, j), i < j, is
// evaluated once. Its force on j is added straight into j's accumulator when j is
// in the same range; when j lies in a later range the pair is a "cross" pair,
// evaluated first (phase A, before a barrier) into a slot that both threads read.
// Every ball then receives its contributions in one fixed order — from the pairs
// (i', p) in ascending i', then its own row in ascending j, then its walls — on
// any number of threads, so results are bitwise independent of the thread count.
// A ball is complete once its own row is done (later balls never read it in this
// step), so it is integrated right there unless an observer needs the forces.

namespace {

// What the contact law reads at a ball pair, loaded once per pass into the
// thread's registers and stack. Read through the World's members, every store
// into the history (pair_touch is a byte, which may alias anything) made the
// compiler reload each array's address and each constant for the next pair.
struct PairLawInputs {
  const Vec3* position;
  const Vec3* velocity;
  const Vec3* omega;
  const double* mass;
  const std::int32_t* material;
  const detail::PairProps* props;  // [material a * materials + material b]
  std::size_t materials;
  std::uint8_t* touched;  // history.pair_touch
  Vec3* shear;            // history.pair_shear
  double* relax_offset;   // relax.pair while initial overlaps relax, else null
  double relax_factor;
  ContactModel contact;
  double dt;
  double max_overlap_fraction;  // the watchdog's
  bool damped;
};

// Pair k = (i, j) whose test found them touching (d = xj - xi, dist2 = |d|^2): the
// contact law; false when the relaxing initial overlap leaves no force.
template <class Law>
[[gnu::always_inline]] inline bool evaluateTouchingPair(const PairLawInputs& in, std::size_t i, std::uint32_t j,
                                                        std::uint32_t k, const Vec3& xi, double ri, double rj,
                                                        const Vec3& d, double dist2, Vec3& fi, Vec3& ti, Vec3& fj,
                                                        Vec3& tj, StepChecks& c) {
  Vec3 n, cp;
  double overlap;
  touchingBallGeometry(xi, d, dist2, ri, rj, n, overlap, cp);
  detail::ContactGeometry g;
  g.normal = n;
  g.overlap = overlap;
  if (in.relax_offset) {
    // Initial overlap being relaxed: the law sees only the overlap beyond the offset.
    g.overlap = relaxedOverlap(overlap, in.relax_factor, in.relax_offset[k]);
    if (g.overlap <= 0) {
      in.touched[k] = 0;
      in.shear[k].setZero();
      return false;
    }
  }
  const Vec3 ai = cp - xi, aj = cp - in.position[j];
  g.rel_velocity = (in.velocity[j] + in.omega[j].cross(aj)) - (in.velocity[i] + in.omega[i].cross(ai));
  g.r_tilde = effectiveRadius(ri, rj);  // Eq 2-24
  // Only the dashpots read it: a division per contact saved on undamped scenes.
  g.damping_mass = in.damped ? detail::dampingMass(in.contact.damping_mass, in.mass[i], in.mass[j]) : 0.0;
  const detail::PairProps& props =
      in.props[static_cast<std::size_t>(in.material[i]) * in.materials + static_cast<std::size_t>(in.material[j])];
  const detail::ContactResult res = detail::evaluateContact<Law>(props, in.contact, g, in.dt, in.shear[k]);
  fi = res.force;
  ti = ai.cross(res.force);
  fj = -res.force;
  tj = aj.cross(fj);
  in.touched[k] = 1;
  const double r_small = std::min(ri, rj);
  if (g.overlap > in.max_overlap_fraction * r_small)
    mergeWorst(c, g.overlap / r_small, (std::uint64_t(i) << 32) | j);
  return true;
}

}  // namespace

template <class Law>
inline void World::Impl::addWallForces(std::size_t i, Vec3& f, Vec3& t, StepChecks& c) {
  const Vec3 xi = p.position[i];
  const double ri = p.radius[i];
  // One contact (or none) at candidate w; `slotted`: a mesh wall's, whose normal is kept.
  auto contact = [&](std::uint32_t w, std::uint32_t wk, const ContactPoint* touch, bool fresh, bool slotted) {
    if (!touch) {
      history.wall_touch[w] = 0;
      history.wall_shear[w].setZero();
      if (slotted) history.wall_normal[w].setZero();
      if (relax.active()) relax.wall[w] = 0.0;  // separated: a new touch gets the full force
      return;
    }
    if (fresh) history.wall_shear[w].setZero();  // the slot's last contact ended
    if (slotted) history.wall_normal[w] = touch->normal;
    detail::ContactGeometry g;
    g.normal = touch->normal;
    g.overlap = touch->overlap;
    const Vec3 cp = touch->point;
    if (relax.active()) {
      g.overlap = wallOverlap(*touch, w);
      if (g.overlap <= 0) {
        history.wall_touch[w] = 0;
        history.wall_shear[w].setZero();
        return;
      }
    }
    const Vec3 ai = cp - xi;
    const Vec3 v_wall = walls[wk].contactVelocityAt(cp, g.normal);  // the spin: tangential only
    g.rel_velocity = v_wall - (p.velocity[i] + p.omega[i].cross(ai));
    g.r_tilde = ri;            // mirror-image ball (ref §4.2)
    g.damping_mass = p.mass[i];  // ball–wall dashpot uses the ball's mass (Eq 2-18)
    const detail::ContactResult res =
        detail::evaluateContact<Law>(wallProps(i, wk), model.contact, g, dt, history.wall_shear[w]);
    f += res.force;
    t += ai.cross(res.force);
    history.wall_touch[w] = 1;
    if (!guard.wall_work.empty() && guard.wall_moving[wk]) {
      // Power of the wall on the ball, F . v_wall (the energy watchdog's work input).
      const double dw = dt * res.force.dot(v_wall);
      guard.wall_work[i] += dw;
      guard.wall_work_gross[i] += std::abs(dw);
    }
    if (g.overlap > model.watchdog.max_overlap_fraction * ri)
      mergeWorst(c, g.overlap / ri, (std::uint64_t(i) << 32) | kWallBit | wk);
  };
  for (std::uint32_t w = nb.wall_offset[i]; w < nb.wall_offset[i + 1];) {
    const std::uint32_t wk = nb.wall_index[w];
    if (model.walls[wk].shape != WallShape::Mesh) {
      // A plane or polygon: its one contact, as wallTouches gives it, without the
      // slots' scratch (the pass alone searches a mesh's triangles bounded).
      ContactPoint touch;
      const bool touching = ballWallTouch(walls[wk], model.walls[wk], xi, ri, touch);
      contact(w, wk, touching ? &touch : nullptr, false, false);
      ++w;
      continue;
    }
    // A mesh wall: its slots in a row, each touch in its slot (wall_touches.cpp).
    WallTouches touches;
    meshWallTouches(walls[wk], i, w, touches, true);
    for (std::uint32_t s = 0; s < touches.slots; ++s)
      contact(w + s, wk, touches.has[s] ? &touches.touch[s] : nullptr, touches.fresh[s], true);
    w += touches.slots;
  }
}

template <class Law>
void World::Impl::forcePass(bool integrate_now, double h, StepChecks& merged) {
  const int team = static_cast<int>(scratch.range_begin.size()) - 1;
  const bool crossing = team > 1;  // one thread: no cross slots (assignRanges)
  // Clump members are integrated with their clump after the pass. A local copy:
  // the stores into the accumulators could alias the member flag otherwise.
  const std::int32_t* const clump_of = has_clumps ? p.clump.data() : nullptr;
#pragma omp parallel num_threads(team)
  {
    const int th = omp_get_thread_num();
    const std::uint32_t b = scratch.range_begin[th], e = scratch.range_begin[th + 1];
    StepChecks local;
    // Pair k of ball i (at xi, radius ri; j its partner): the touch test, an apart
    // pair's history cleared, a touching pair's law; both phases take this path.
    // It reads through local pointers with ball i in registers: through the members,
    // every store into the history (a byte, which may alias anything) made the
    // compiler reload the arrays' addresses and the ball's position for the next
    // pair, on the chain of loads each apart pair waits for.
    const Vec3* const position = p.position.data();  // the fused kick writes it: not restrict
    const double* __restrict const radius = p.radius.data();
    const std::uint32_t* __restrict const partner = nb.pairs.partner.data();
    std::uint8_t* const touched = history.pair_touch.data();
    Vec3* const shear = history.pair_shear.data();
    double* const relax_offset = relax.active() ? relax.pair.data() : nullptr;
    const PairLawInputs law_inputs{position,
                                   p.velocity.data(),
                                   p.omega.data(),
                                   p.mass.data(),
                                   p.material.data(),
                                   ball_ball.data(),
                                   nm,
                                   touched,
                                   shear,
                                   relax_offset,
                                   relax.factor,
                                   model.contact,
                                   dt,
                                   model.watchdog.max_overlap_fraction,
                                   model.contact.damping_normal > 0 || model.contact.damping_shear > 0};
    Vec3* const acc_force = scratch.acc_force.data();
    Vec3* const acc_torque = scratch.acc_torque.data();
    auto evaluatePair = [&](std::uint32_t i, const Vec3& xi, double ri, std::uint32_t k, std::uint32_t j, Vec3& fi,
                            Vec3& ti, Vec3& fj, Vec3& tj) __attribute__((always_inline)) {
      const double rj = radius[j];
      const Vec3 d = position[j] - xi;
      const double dist2 = d.squaredNorm();
      if (ballsApart(dist2, ri, rj)) {
        touched[k] = 0;
        shear[k].setZero();
        if (relax_offset) relax_offset[k] = 0.0;  // separated: a new touch gets the full force
        return false;
      }
      return evaluateTouchingPair<Law>(law_inputs, i, j, k, xi, ri, rj, d, dist2, fi, ti, fj, tj, local);
    };
    // Phase A: pairs whose second ball belongs to a later range (their slots are
    // the thread's, in the order of its rows; none on one thread).
    if (crossing) {
      for (std::uint32_t s = scratch.cross_begin[th]; s < scratch.cross_begin[th + 1]; ++s) {
        ForceScratch::CrossSlot& slot = scratch.cross[s];
        const std::uint32_t i = scratch.cross_ball[s], k = scratch.cross_pair[s];
        evaluatePair(i, position[i], radius[i], k, partner[k], slot.fi, slot.ti, slot.fj, slot.tj);
      }
#pragma omp barrier
    }
    // Phase B: start every ball of the range with the cross contributions it
    // receives (pairs (i', q), i' < b, ascending i'); none on one thread.
    for (std::uint32_t q = b; q < e; ++q) {
      acc_force[q].setZero();
      acc_torque[q].setZero();
    }
    if (crossing)
      for (std::uint32_t r = scratch.receive_begin[th]; r < scratch.receive_begin[th + 1]; ++r) {
        const std::uint32_t s = scratch.receive_slot[r];
        if (!touched[scratch.cross_pair[s]]) continue;
        const std::uint32_t q = scratch.receive_ball[r];
        acc_force[q] += scratch.cross[s].fj;
        acc_torque[q] += scratch.cross[s].tj;
      }
    // ...then every ball's own row (scattering to partners in the range) and walls.
    // A partner past the range is a cross pair, met in slot order (assignRanges).
    std::uint32_t next_slot = crossing ? scratch.cross_begin[th] : 0;
    for (std::uint32_t i = b; i < e; ++i) {
      Vec3 f = acc_force[i], t = acc_torque[i];
      const Vec3 xi = position[i];
      const double ri = radius[i];
      const std::uint32_t row_end = nb.pairs.row_offset[i + 1];
      for (std::uint32_t k = nb.pairs.row_offset[i]; k < row_end; ++k) {
        const std::uint32_t j = partner[k];
        if (j >= e) {  // never on one thread (e = n)
          const std::uint32_t s = next_slot++;
          if (!touched[k]) continue;
          f += scratch.cross[s].fi;
          t += scratch.cross[s].ti;
          continue;
        }
        Vec3 fi, ti, fj, tj;
        if (!evaluatePair(i, xi, ri, k, j, fi, ti, fj, tj)) continue;
        f += fi;
        t += ti;
        acc_force[j] += fj;
        acc_torque[j] += tj;
      }
      addWallForces<Law>(i, f, t, local);
      if (integrate_now && !(clump_of && clump_of[i] >= 0)) {
        integrate(i, f, t, h, local);
      } else {
        acc_force[i] = f;
        acc_torque[i] = t;
      }
    }
#pragma omp critical
    mergeChecks(merged, local);
  }
}

void World::Impl::forceStage(const StepPlan& plan, StepChecks& checks) {
  if (model.contact.law == ContactLaw::Linear)
    forcePass<detail::LinearLaw>(plan.fused, plan.kick, checks);
  else
    forcePass<detail::HertzMindlinLaw>(plan.fused, plan.kick, checks);
  // Clumps sum their members' forces once every member is complete.
  if (plan.fused && has_clumps) integrateClumps(plan.kick, checks);
}

}  // namespace rocklab::sim
