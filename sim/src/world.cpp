// World::step as its stages, in order (the list at the head of world.h), and
// the public accessors. Each stage's body lives in src/stages/<stage>.cpp.
#include <sstream>

#include "world_impl.h"

namespace rocklab::sim {

std::string fmtNum(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

const char* stageName(Stage s) {
  switch (s) {
    case Stage::Prepare: return "prepare";
    case Stage::Neighbours: return "neighbours";
    case Stage::Forces: return "forces";
    case Stage::Bonds: return "bonds";
    case Stage::ExtraForces: return "extra_forces";
    case Stage::Observe: return "observe";
    case Stage::Watchdog: return "watchdog";
    case Stage::Integrate: return "integrate";
    case Stage::Count: break;
  }
  return "?";
}

// ---------------------------------------------------------------------------
// One step

StepPlan World::Impl::planStep(bool observed) const {
  StepPlan plan;
  plan.kick = half_kick_pending ? 0.5 * dt : dt;
  const int interval = std::max(1, model.watchdog.check_interval);
  plan.energy_due = (step % static_cast<std::uint64_t>(interval)) == 0 && energyCheckApplies();
  int network_every = std::max(1, model.watchdog.network_interval);
  if (dt > audit.automatic * (1.0 + 1e-12)) network_every = std::min(network_every, interval);  // a forced step
  plan.network_due =
      model.watchdog.network_iterations > 0 && step % static_cast<std::uint64_t>(network_every) == 0;
  plan.observe = observed || plan.energy_due || plan.network_due;
  plan.bonds = bonds.intact > 0;
  // The kick needs every force of the step: fused into the contact pass only
  // when no snapshot is taken before it and no bond or contribution adds forces after it.
  plan.fused = !plan.observe && !plan.bonds && contributions.empty();
  return plan;
}

void World::Impl::doStep(const std::function<void(const Snapshot&)>& observer) {
  // The engine's own wall time (the observer's is the caller's), for the team tuner.
  const auto start = std::chrono::steady_clock::now();
  double observer_seconds = 0.0;
  {
    StageTimer timer(stageSeconds(Stage::Prepare));
    prepareStage();  // 1
  }
  {
    StageTimer timer(stageSeconds(Stage::Neighbours));
    neighbourStage();  // 2
  }
  const StepPlan plan = planStep(static_cast<bool>(observer));
  StepChecks checks;
  {
    StageTimer timer(stageSeconds(Stage::Forces));
    forceStage(plan, checks);  // 3
    forces_evaluated = true;
  }
  if (plan.bonds) {
    StageTimer timer(stageSeconds(Stage::Bonds));
    bondStage(checks);  // 4
  }
  if (!contributions.empty()) {
    StageTimer timer(stageSeconds(Stage::ExtraForces));
    extraForceStage();  // 5
  }
  if (plan.observe) {
    StageTimer timer(stageSeconds(Stage::Observe));
    observeStage();  // 6
  }
  {
    StageTimer timer(stageSeconds(Stage::Watchdog));
    watchdogStage(plan, checks);  // 7
  }
  if (observer) {
    // The whole-step snapshot, before the kick; the observer's own time is the caller's.
    const auto observer_start = std::chrono::steady_clock::now();
    std::vector<Vec3> total_force;
    std::vector<std::uint8_t> wall_active;
    observer(snapshot(total_force, wall_active));
    observer_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - observer_start).count();
  }
  {
    StageTimer timer(stageSeconds(Stage::Integrate));
    integrateStage(plan, checks);  // 8
    finishStep(checks);
  }
  if (team_policy == TeamPolicy::Adaptive && teamToChoose()) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - observer_seconds;
    if (tuner.stepDone(seconds)) teamChanged();
    stats.team_probes = tuner.probes();
    stats.team_switches = tuner.switches();
    stats.single_thread_steps = tuner.singleSteps();
  }
}

void World::step(const std::function<void(const Snapshot&)>& observer) { impl_->doStep(observer); }

void World::addForceContribution(std::shared_ptr<ForceContribution> contribution) {
  if (!contribution) throw std::invalid_argument("addForceContribution: null contribution");
  impl_->contributions.push_back(std::move(contribution));
}

double World::time() const { return impl_->time; }
std::uint64_t World::stepCount() const { return impl_->step; }
double World::dt() const { return impl_->dt; }
double World::movingWallWork() const {
  double work = impl_->guard.wall_work_carried;
  for (const double w : impl_->guard.wall_work) work += w;
  return work;
}
const Model& World::model() const { return impl_->model; }
const ParticleState& World::particles() const { return impl_->p; }
const TimestepAudit& World::timestepAudit() const { return impl_->audit; }
const WorldStats& World::stats() const { return impl_->stats; }
int World::threads() const { return impl_->teamSize(); }
int World::fullTeam() const { return impl_->fullTeam(); }
void World::setTeamPolicy(TeamPolicy policy) {
  impl_->team_policy = policy;
  impl_->teamChanged();
}
int World::bondThreads() const { return impl_->bondTeamSize(); }
Vec3 World::gravity() const { return impl_->gravity; }
const BondState& World::bonds() const { return impl_->bonds.state; }
std::size_t World::intactBonds() const { return impl_->bonds.intact; }
const std::vector<BondBreak>& World::bondBreaks() const { return impl_->bonds.breaks; }

WorldState World::exportState() const {
  const Impl& w = *impl_;
  WorldState s;
  s.time = w.time;
  s.step = w.step;
  s.dt = w.dt;
  s.half_kick_pending = w.half_kick_pending;
  s.particles = w.p;
  s.bonds = w.bonds.state;
  s.moving_wall_work = movingWallWork();
  for (std::size_t i = 0; i + 1 < w.nb.pairs.row_offset.size(); ++i)
    for (std::uint32_t k = w.nb.pairs.row_offset[i]; k < w.nb.pairs.row_offset[i + 1]; ++k)
      if (!w.history.pair_shear[k].isZero(0) || (w.relax.active() && w.relax.pair[k] > 0))
        s.pair_history.push_back({static_cast<std::uint32_t>(i), w.nb.pairs.partner[k], w.history.pair_shear[k],
                                  w.relax.active() ? w.relax.pair[k] : 0.0});
  // Pairs of contact bonds broken in the last step, not yet in the pair list.
  for (const PairHistory& h : w.bonds.handover)
    if (!h.shear.isZero(0)) s.pair_history.push_back(h);
  for (std::size_t i = 0; i + 1 < w.nb.wall_offset.size(); ++i)
    for (std::uint32_t c = w.nb.wall_offset[i]; c < w.nb.wall_offset[i + 1]; ++c) {
      const Vec3 normal = w.history.wall_normal.empty() ? Vec3::Zero() : w.history.wall_normal[c];
      if (!w.history.wall_shear[c].isZero(0) || (w.relax.active() && w.relax.wall[c] > 0) || !normal.isZero(0))
        s.wall_history.push_back({static_cast<std::uint32_t>(i), w.nb.wall_index[c], w.history.wall_shear[c],
                                  w.relax.active() ? w.relax.wall[c] : 0.0, w.nb.wall_slot[c], normal});
    }
  return s;
}

std::uint64_t World::stateHash() const {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  auto mix = [&h](const std::vector<Vec3>& a) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(a.data());
    for (std::size_t k = 0; k < a.size() * sizeof(Vec3); ++k) {
      h ^= bytes[k];
      h *= 1099511628211ull;
    }
  };
  mix(impl_->p.position);
  mix(impl_->p.velocity);
  mix(impl_->p.omega);
  mix(impl_->p.clumps.angular_momentum);
  return h;
}

}  // namespace rocklab::sim
