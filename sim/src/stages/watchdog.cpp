#include "../world_impl.h"

#include <sstream>

namespace rocklab::sim {

// Stage 7, watchdog: stops the run (WatchdogError, a message naming the body,
// the time and the setting to change) on an overlap beyond
// watchdog.max_overlap_fraction (every step), energy growth beyond the work of
// the moving walls (when computed) and a step the contact network cannot take
// (network_check.cpp, when due). The non-finite guard runs after the drift
// (integrate.cpp, finishStep).
// Reads: the step checks of stage 3, obs.energy, the contact lists and history.
// Writes: the energy reference (guard), stats.network_*.

void World::Impl::watchdogStage(const StepPlan& plan, const StepChecks& checks) {
  checkOverlap(checks);
  if (guard.check_travel) checkTravel();
  if (!plan.observe) return;
  // Checked whenever the energy is computed, not only every check_interval
  // steps: an observer may end the run (a drop test ends at the rebound)
  // before the next scheduled check would see a blow-up.
  if (energyCheckApplies()) checkEnergy(obs.energy);
  if (plan.network_due) checkNetworkStep();
}

std::string World::Impl::stepAdvice() const {
  std::ostringstream s;
  s << "The step dt = " << fmtNum(dt) << " s is " << fmtNum(dt / audit.critical)
    << " x the critical step " << fmtNum(audit.critical) << " s";
  if (model.timestep.dt > 0)
    s << " (set by timestep.dt); lower timestep.dt";
  else
    s << "; lower timestep.safety_factor (now " << model.timestep.safety_factor << ")";
  s << ", or soften the contacts (materials kn/ks or shear_modulus).";
  return s.str();
}

void World::Impl::checkOverlap(const StepChecks& checks) const {
  if (checks.worst_overlap <= model.watchdog.max_overlap_fraction) return;
  const auto i = static_cast<std::size_t>(checks.worst_key >> 32);
  const auto low = static_cast<std::uint32_t>(checks.worst_key & 0xffffffffu);
  std::ostringstream s;
  s << "watchdog: at t = " << fmtNum(time) << " s (step " << step << ") the overlap of particle "
    << p.id[i];
  if (low & kWallBit)
    s << " with wall '" << model.walls[low & ~kWallBit].name << "'";
  else
    s << " with particle " << p.id[low];
  s << " is " << fmtNum(checks.worst_overlap)
    << " of the smaller radius, above watchdog.max_overlap_fraction = "
    << model.watchdog.max_overlap_fraction
    << ". Either the particles were created overlapping (relaxation.steps eases initial overlaps apart), "
       "the contacts are too soft for the loads or impact speeds (a linear impact at v overlaps "
       "v sqrt(m/k): stiffen them), "
    << ((low & kWallBit) ? "the ball is pinched where walls close to less than its size (a crusher's gap "
                           "without breakage: [experiment.breakage]), "
                         : "")
    << "or the step is too large. " << stepAdvice();
  throw WatchdogError(s.str());
}

void World::Impl::checkFinite() const {
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.position[i].allFinite() && p.velocity[i].allFinite()) continue;
    std::ostringstream s;
    s << "watchdog: particle " << p.id[i] << " has a non-finite position or velocity at t = "
      << fmtNum(time) << " s (step " << step << "): the run blew up. " << stepAdvice();
    throw WatchdogError(s.str());
  }
}

void World::Impl::checkTravel() {
  // The last drift moved ball i by dt |v_i(t - dt/2)| (at step 0: the coming one).
  std::size_t worst = p.size();
  double worst_ratio = 1.0;  // travel / radius
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double ratio = p.velocity[i].norm() * dt / p.radius[i];
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      worst = i;
    }
  }
  if (worst == p.size()) return;
  ++stats.far_travel_steps;
  if (!stats.far_travel.empty()) return;
  std::ostringstream s;
  s << "at t = " << fmtNum(time) << " s (step " << step << ") particle " << p.id[worst] << " moved "
    << fmtNum(worst_ratio * p.radius[worst]) << " m in one step, " << fmtNum(worst_ratio)
    << " x its radius: it can pass through a wall or a ball without touching it. The step dt = " << fmtNum(dt)
    << " s is forced above the automatic step " << fmtNum(audit.automatic)
    << " s (timestep.allow_unsafe); results after this are not trustworthy";
  stats.far_travel = s.str();
}

bool World::Impl::energyCheckApplies() const {
  // Moving walls do work: it is counted (wall_work) and allowed for in checkEnergy.
  // Relaxing initial overlaps does work on the system (the offsets shrink).
  if (relax.active()) return false;
  return model.watchdog.max_energy_growth > 0 && p.size() > 0;
}

void World::Impl::checkEnergy(const Energy& e) {
  if (!energyCheckApplies()) return;
  if (!guard.energy_ref_valid) {
    // Scale: the energy the system could release by falling across its own extent.
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    double mass = 0, r_max = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      lo = lo.cwiseMin(p.position[i]);
      hi = hi.cwiseMax(p.position[i]);
      if (!isMember(i)) mass += p.mass[i];
      r_max = std::max(r_max, p.radius[i]);
    }
    for (double m : p.clumps.mass) mass += m;
    const double extent = (hi - lo).norm() + 2 * r_max;
    guard.energy_ref = e.total();
    guard.energy_scale = std::abs(e.kinetic_translational + e.kinetic_rotational + e.elastic) +
                   mass * gravity.norm() * extent;
    guard.energy_ref_valid = guard.energy_scale > 0;
    for (const double w : guard.wall_work) guard.wall_work_carried += w;  // World::movingWallWork keeps it
    std::fill(guard.wall_work.begin(), guard.wall_work.end(), 0.0);
    std::fill(guard.wall_work_gross.begin(), guard.wall_work_gross.end(), 0.0);
    return;
  }
  // Work of the moving walls since the reference, summed in ball order. The
  // allowance grows with the gross work so that the O(dt^2) error of counting it
  // cannot add up to a false alarm in a long run with a working wall (a crusher).
  double work = 0.0, gross = 0.0;
  for (std::size_t i = 0; i < guard.wall_work.size(); ++i) {
    work += guard.wall_work[i];
    gross += guard.wall_work_gross[i];
  }
  const double growth = e.total() - guard.energy_ref - work;
  if (growth <= model.watchdog.max_energy_growth * (guard.energy_scale + gross)) return;
  std::size_t fastest = 0;
  for (std::size_t i = 1; i < p.size(); ++i)
    if (p.velocity[i].squaredNorm() > p.velocity[fastest].squaredNorm()) fastest = i;
  std::ostringstream s;
  s << "watchdog: mechanical energy grew by " << fmtNum(growth) << " J (" << fmtNum(growth / guard.energy_scale)
    << " of its scale " << fmtNum(guard.energy_scale) << " J, limit watchdog.max_energy_growth = "
    << model.watchdog.max_energy_growth << ") at t = " << fmtNum(time) << " s (step " << step << ") "
    << (guard.wall_work.empty() ? std::string("with no work input")
                          : "beyond the " + fmtNum(work) + " J of work done by the moving walls")
    << "; fastest particle " << p.id[fastest] << " at "
    << fmtNum(p.velocity[fastest].norm()) << " m/s. " << stepAdvice();
  throw WatchdogError(s.str());
}

}  // namespace rocklab::sim
