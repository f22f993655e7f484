#include "../world_impl.h"

#include "../rigid_body.h"

namespace rocklab::sim {

// Stage 8, integrate: leapfrog kick and drift (Eq 2-11..2-13) with local
// damping (Eq 2-15) for free balls (World::Impl::integrate, world_impl.h) and
// rigid clumps (Eq 2-44..2-46, free rotation in rigid_body.h), then the clock.
// Reads: scratch.acc_force/acc_torque (contacts and contributions), gravity.
// Writes: positions, velocities, spins, clump state, members placed; time and
// step; the largest displacement (for stage 1); stops on a non-finite state.

void World::Impl::integrateStage(const StepPlan& plan, StepChecks& merged) {
  if (plan.fused) return;  // done inside the contact pass (stage 3)
  const std::size_t n = p.size();
#pragma omp parallel num_threads(teamSize())
  {
    StepChecks local;
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i)
      if (!isMember(i)) integrate(i, scratch.acc_force[i], scratch.acc_torque[i], plan.kick, local);
#pragma omp critical
    mergeChecks(merged, local);
  }
  if (has_clumps) integrateClumps(plan.kick, merged);
}

void World::Impl::finishStep(const StepChecks& checks) {
  half_kick_pending = false;
  time = static_cast<double>(step + 1) * dt;  // no accumulated round-off in t
  ++step;
  nb.last_max_disp2 = checks.max_disp2;
  if (checks.non_finite) checkFinite();
}

/// Resultant contact force and moment about the centre of mass (Eq 2-44, 2-46),
/// summed over the members in their fixed order.
void World::Impl::clumpLoad(std::size_t c, Vec3& force, Vec3& torque) const {
  const ClumpState& k = p.clumps;
  force.setZero();
  torque.setZero();
  for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
    const std::uint32_t i = k.member_ball[m];
    force += scratch.acc_force[i];
    torque += scratch.acc_torque[i] + (p.position[i] - k.position[c]).cross(scratch.acc_force[i]);
  }
}

void World::Impl::integrateClumps(double h, StepChecks& merged) {
  ClumpState& k = p.clumps;
  const double alpha = model.contact.local_damping;
  // Bodies go in blocks of kBatch so that their free rotations run interleaved
  // (rotateFreeBatch): each body's arithmetic is the same as alone.
  constexpr std::size_t kBatch = 4;
  const std::size_t n = k.size(), blocks = (n + kBatch - 1) / kBatch;
#pragma omp parallel num_threads(teamSize())
  {
    StepChecks local;
#pragma omp for schedule(static)
    for (std::size_t block = 0; block < blocks; ++block) {
      const std::size_t first = block * kBatch, count = std::min(kBatch, n - first);
      Quat q[kBatch];
      Vec3 L[kBatch];
      for (std::size_t l = 0; l < count; ++l) {
        const std::size_t c = first + l;
        Vec3 f, t;
        clumpLoad(c, f, t);
        f += gravity * k.mass[c];
        if (alpha > 0) {
          // Local damping (Eq 2-15, sign form) on the body's generalised force.
          const Vec3 w = detail::angularVelocity(k.orientation[c], k.inertia[c], k.angular_momentum[c]);
          for (int a = 0; a < 3; ++a) {
            f[a] -= alpha * std::abs(f[a]) * ((k.velocity[c][a] > 0) - (k.velocity[c][a] < 0));
            t[a] -= alpha * std::abs(t[a]) * ((w[a] > 0) - (w[a] < 0));
          }
        }
        // Formed and checked in registers, then stored (as integrate() does for a ball).
        const Vec3 v = k.velocity[c] + (h / k.mass[c]) * f;  // Eq 2-11 for the body
        L[l] = k.angular_momentum[c] + h * t;                 // Eq 2-45
        const Vec3 x = k.position[c] + dt * v;                // Eq 2-13
        if (!x.allFinite() || !v.allFinite() || !L[l].allFinite()) local.non_finite = true;
        k.velocity[c] = v;
        k.angular_momentum[c] = L[l];
        k.position[c] = x;
        q[l] = k.orientation[c];
      }
      if (count == kBatch) detail::rotateFreeBatch<kBatch>(q, &k.inertia[first], L, dt);
      else
        for (std::size_t l = 0; l < count; ++l) detail::rotateFree(q[l], k.inertia[first + l], L[l], dt);
      for (std::size_t l = 0; l < count; ++l) {
        const std::size_t c = first + l;
        k.orientation[c] = q[l];
        local.max_disp2 = std::max(local.max_disp2, placeMembers(c, q[l], k.position[c], k.velocity[c], L[l]));
      }
    }
#pragma omp critical
    mergeChecks(merged, local);
  }
}

}  // namespace rocklab::sim
