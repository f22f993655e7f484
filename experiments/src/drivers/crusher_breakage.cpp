#include "drivers/crusher_breakage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/json_text.h"
#include "rocklab/sim/particle_stress.h"
#include "rocklab/sim/timestep.h"
#include "rocklab/sim/world.h"

namespace rocklab::experiments {

using detail::Range;
using geometry::Vec3;

void readBreakageSettings(detail::TableReader& experiment_table, BreakageSettings& s) {
  auto b = experiment_table.table("breakage");
  if (!b) return;
  s.enabled = true;
  s.check_interval = b->number("check_interval", s.check_interval, Range::nonNegative());
  using Start = BreakageSettings::Start;
  s.start = b->choice("start", s.start,
                      {{Start::Feed, breakageStartName(Start::Feed)}, {Start::Release, breakageStartName(Start::Release)}});
  s.strength.q_ref = b->number("q_ref", s.strength.q_ref, Range::positive());
  s.strength.d_ref = b->number("d_ref", s.strength.d_ref, Range::positive());
  s.strength.size_exponent = b->number("size_exponent", s.strength.size_exponent);
  s.strength.weibull_modulus = b->number("weibull_modulus", s.strength.weibull_modulus, Range::positive());
  s.min_diameter = b->number("min_diameter", s.min_diameter, Range::positive());
  s.mode = b->choice("mode", s.mode, {{crusher::SplitMode::Triple, "triple"}, {crusher::SplitMode::Equal, "equal"}});
  s.offsets = b->has("offsets") ? b->numberList("offsets") : crusher::defaultOffsets(s.mode);
  if (const std::string problem = crusher::offsetsProblem(s.mode, s.offsets); !problem.empty())
    b->fail("offsets", problem);
  s.youngs_modulus = b->number("youngs_modulus", s.youngs_modulus, Range::positive());
  s.class_ratio = b->number("class_ratio", s.class_ratio,
                            {1.0, std::numeric_limits<double>::infinity(), true, false});
  crusher::FreezeSettings& f = s.freeze;
  using crusher::FreezeScope;
  f.scope = b->choice("freeze_scope", f.scope,
                      {{FreezeScope::Local, crusher::freezeScopeName(FreezeScope::Local)},
                       {FreezeScope::All, crusher::freezeScopeName(FreezeScope::All)}});
  f.held_density = b->number("freeze_held_density", f.held_density, Range::positive());
  f.local_reach = b->number("freeze_local_reach", f.local_reach, Range::positive());
  f.density = b->number("freeze_density", f.density, Range::positive());
  f.stiffness = b->number("freeze_stiffness", f.stiffness, Range::positive());
  f.local_damping = b->number("freeze_local_damping", f.local_damping, {0.0, 1.0, false, true});
  f.overlap_fraction = b->number("freeze_overlap_fraction", f.overlap_fraction, Range::nonNegative());
  f.kinetic_fraction = b->number("freeze_kinetic_fraction", f.kinetic_fraction, Range::nonNegative());
  f.stall_tolerance = b->number("freeze_stall_tolerance", f.stall_tolerance, {0.0, 1.0, false, true});
  f.stall_window = b->number("freeze_stall_window", f.stall_window, Range::closed(0.0, 1e6));
  f.stall_max_overlap = b->number("freeze_stall_max_overlap", f.stall_max_overlap, Range::nonNegative());
  f.max_contact_times = b->number("freeze_max_contact_times", f.max_contact_times, Range::closed(0.0, 1e12));
  f.jam_contact_times = b->number("freeze_jam_contact_times", f.jam_contact_times, Range::closed(0.0, 1e12));
  f.max_cycles = b->integer("freeze_max_cycles", f.max_cycles, {1.0, 1e12});
  f.check_cycles = b->integer("freeze_check_cycles", f.check_cycles, {1.0, 1e9});
  // The boolean before freeze_crowded (until 2026-12-04): a scene that still has it
  // is told the new key rather than "unknown key".
  if (b->has("freeze_defer_crowded"))
    b->fail("freeze_defer_crowded", "replaced by freeze_crowded: true is \"defer\", false is \"stop\"");
  using crusher::CrowdedOutcome;
  std::vector<std::pair<CrowdedOutcome, std::string>> outcomes;
  for (const CrowdedOutcome o : {CrowdedOutcome::Break, CrowdedOutcome::Defer, CrowdedOutcome::Stop})
    outcomes.emplace_back(o, crusher::crowdedOutcomeName(o));
  f.crowded = b->choice("freeze_crowded", f.crowded, outcomes);
  s.crowded_max_overlap = b->number("freeze_crowded_max_overlap", s.crowded_max_overlap, Range::nonNegative());
  using Bound = BreakageSettings::CrowdedBound;
  s.crowded_bound = b->choice("freeze_crowded_bound", s.crowded_bound,
                              {{Bound::Energy, crowdedBoundName(Bound::Energy)},
                               {Bound::Overlap, crowdedBoundName(Bound::Overlap)}});
  s.crowded_energy_factor =
      b->number("freeze_crowded_energy_factor", s.crowded_energy_factor, Range::nonNegative());
  s.defer_time = b->number("defer_time", s.defer_time, Range::nonNegative());
  b->finish();
}

const char* crowdedBoundName(BreakageSettings::CrowdedBound bound) {
  return bound == BreakageSettings::CrowdedBound::Overlap ? "overlap" : "energy";
}

const char* breakageStartName(BreakageSettings::Start start) {
  return start == BreakageSettings::Start::Release ? "release" : "feed";
}

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(BreakageEvent, time, parent, diameter, q, strength, fragments, freeze_cycles,
                                   freeze_end, freeze_overlap, freeze_contact_times, kinetic_jump, mass, parent_energy,
                                   handed_back_energy, fragment_diameters, fragment_masses)

namespace {

// The kinetic-energy jump after a breakage is followed for this many contact
// times pi sqrt(m/k) of the heaviest fragment at its rock stiffness: an overlap
// handed back is spent within about one (the pair's spring in series and its
// reduced mass keep the same ratio), and a longer window takes in more of the
// chamber's own changes (the mantle's work, other impacts).
constexpr double kJumpWindow = 5;

/// Adds sign × the elastic energy (J) of the contacts in `c` that involve a ball
/// flagged in `balls` and none flagged in `skip` (empty: none), pairs then walls.
void addContactEnergy(double& sum, double sign, const sim::TouchingContacts& c, const std::vector<bool>& balls,
                      const std::vector<bool>& skip = {}) {
  const auto skipped = [&](std::uint32_t i) { return !skip.empty() && skip[i]; };
  for (std::size_t k = 0; k < c.pairs.size(); ++k) {
    const auto [i, j] = c.pairs[k];
    if ((balls[i] || balls[j]) && !skipped(i) && !skipped(j)) sum += sign * c.pair_energy[k];
  }
  for (std::size_t k = 0; k < c.walls.size(); ++k)
    if (balls[c.walls[k].first] && !skipped(c.walls[k].first)) sum += sign * c.wall_energy[k];
}

std::string mm(double metres) {
  std::ostringstream s;
  s.precision(4);
  s << metres * 1e3;
  return s.str();
}

}  // namespace

CrusherBreakage::CrusherBreakage(BreakageSettings settings, std::uint64_t seed)
    : s_(std::move(settings)), seed_(seed) {}

int CrusherBreakage::fragmentMaterial(sim::Model& model, int material, double diameter) {
  const auto base_it = base_of_.find(material);
  const int base = base_it == base_of_.end() ? material : base_it->second;
  const int size_class = static_cast<int>(std::floor(std::log(diameter / s_.min_diameter) / std::log(s_.class_ratio)));
  const auto [it, added] = class_material_.try_emplace({base, size_class}, static_cast<int>(model.materials.size()));
  if (!added) return it->second;
  model.materials.push_back(classMaterial(model.materials[base], base, size_class));
  base_of_[it->second] = base;
  return it->second;
}

sim::Material CrusherBreakage::classMaterial(const sim::Material& feed, int feed_index, int size_class) const {
  // k = 4 R E_c (Eq 6-14) at the class's geometric middle; the shear stiffness in
  // the feed material's ratio.
  sim::Material m = feed;
  const double lo = s_.min_diameter * std::pow(s_.class_ratio, size_class), hi = lo * s_.class_ratio;
  m.name = feed.name + " fragments " + mm(lo) + "-" + mm(hi) + " mm";
  m.kn = 2.0 * lo * std::sqrt(s_.class_ratio) * s_.youngs_modulus;
  m.ks = m.kn * (feed.kn > 0 ? feed.ks / feed.kn : 1.0);
  m.made_from = feed_index;  // drawn in the feed's colour (run.h5 /materials)
  return m;
}

nlohmann::json CrusherBreakage::saveState() const {
  nlohmann::json j;
  savedFields(*this, [&j](const char* key, const auto& value) { j[key] = value; });
  j["jump_watch"] = jump_watch_ ? nlohmann::json(*jump_watch_) : nlohmann::json(nullptr);
  return j;
}

void CrusherBreakage::restoreState(const nlohmann::json& j, sim::Model& model) {
  savedFields(*this, [&j](const char* key, auto& value) { j.at(key).get_to(value); });
  jump_watch_.reset();
  if (!j.at("jump_watch").is_null()) jump_watch_ = j.at("jump_watch").get<JumpWatch>();
  if (every_ == 0) throw std::invalid_argument("breakage check every 0 steps (allowed: at least 1)");
  // The fragment materials in the order the run added them after the scene's.
  std::vector<std::pair<int, std::pair<int, int>>> added;  // (material, (feed material, class))
  for (const auto& [key, material] : class_material_) added.push_back({material, key});
  std::sort(added.begin(), added.end());
  base_of_.clear();
  for (const auto& [material, key] : added) {
    const auto [base, size_class] = key;
    if (material != static_cast<int>(model.materials.size()) || base < 0 || base >= material)
      throw std::invalid_argument("fragment material " + std::to_string(material) + " of feed material " +
                                  std::to_string(base) + " does not follow the scene's " +
                                  std::to_string(model.materials.size()) + " materials");
    model.materials.push_back(classMaterial(model.materials[base], base, size_class));
    base_of_[material] = base;
  }
}

void CrusherBreakage::start(const sim::World& world) {
  const sim::Model& model = world.model();
  if (model.contact.law != sim::ContactLaw::Linear)
    throw std::invalid_argument(
        "experiment.breakage needs contact.law = \"linear\" (Table 6.2: k = 4 R E_c per size class)");
  const sim::ParticleState& p = world.particles();
  if (p.clumps.size() > 0)
    throw std::invalid_argument(
        "experiment.breakage splits free spheres (§g.6); this scene has clumps, whose member balls it cannot split");
  check_interval_ = s_.check_interval > 0 ? s_.check_interval : automaticCheckInterval(world.model(), p);
  every_ = stepsIn(check_interval_, world.dt());
  for (const std::uint64_t id : p.id) next_id_ = std::max(next_id_, id + 1);
  // The step must hold the smallest fragment the breakage can make: the lightest
  // piece of a ball of min_diameter, of each feed material, on its class's stiffness.
  const std::vector<double> fractions = crusher::massFractions(s_.mode);
  const double d = s_.min_diameter * std::cbrt(*std::min_element(fractions.begin(), fractions.end()));
  sim::Model probe = model;
  // The probe's automatic step is what is asked for: a scene's own timestep.dt is
  // compared below, with the message naming the breakage's keys (the engine's
  // audit would refuse it first, naming only timestep.dt).
  probe.timestep.dt = 0.0;
  sim::ParticleState balls = p;
  CrusherBreakage scratch = *this;  // the probe's materials must not enter the run's table
  for (const int material : std::set<int>(p.material.begin(), p.material.end())) {
    const int m = scratch.fragmentMaterial(probe, material, d);
    sim::appendFreeSphere(balls, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), d / 2, m},
                          sim::sphereMass(model.materials[material].density, d / 2),
                          std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(material));
  }
  if (balls.size() == p.size()) return;
  const sim::TimestepAudit audit = sim::auditTimestep(probe, balls);
  if (world.dt() > audit.automatic * (1 + 1e-9)) {
    std::ostringstream msg;
    msg << "experiment.breakage: the step dt = " << world.dt() << " s is too long for the smallest fragment the "
        << "breakage can make (d = " << d * 1e3 << " mm: min_diameter = " << s_.min_diameter * 1e3
        << " mm split by mode, k = " << probe.materials.back().kn
        << " N/m from youngs_modulus): its stable step is " << audit.automatic
        << " s. Set timestep.dt to at most that, or raise experiment.breakage.min_diameter or lower "
           "experiment.breakage.youngs_modulus";
    throw std::invalid_argument(msg.str());
  }
}

double CrusherBreakage::automaticCheckInterval(const sim::Model& model, const sim::ParticleState& p) const {
  // [X] of §g.6: the check frequency is not stated. An impact loads a ball for its
  // contact time, pi sqrt(m / k) on a rigid wall (undamped linear spring); checked
  // every quarter of it, some check falls within 3/8 of the contact's middle and
  // sees at least sin(3 pi / 8) = 92 % of its peak force. The shortest contact is
  // the lightest breakable ball's (min_diameter) on the stiffest spring it can
  // have: its feed material's or its fragment class's (k = 4 R E_c, Eq 6-14).
  double interval = std::numeric_limits<double>::infinity();
  sim::Model scratch_model = model;
  CrusherBreakage scratch = *this;
  for (const int material : std::set<int>(p.material.begin(), p.material.end())) {
    const double mass = sim::sphereMass(model.materials[material].density, s_.min_diameter / 2);
    const int fragment = scratch.fragmentMaterial(scratch_model, material, s_.min_diameter);
    const double k = std::max(model.materials[material].kn, scratch_model.materials[fragment].kn);
    interval = std::min(interval, 0.25 * std::numbers::pi * std::sqrt(mass / k));
  }
  return interval;
}

void CrusherBreakage::watchKineticJump(const sim::World& world) {
  if (!jump_watch_) return;
  const sim::ParticleState& p = world.particles();
  std::vector<std::uint32_t> rows(p.size());
  std::iota(rows.begin(), rows.end(), 0u);
  const double jump = crusher::kineticEnergy(p, rows) - jump_watch_->before;
  for (std::size_t k = jump_watch_->first_event; k < jump_watch_->end_event; ++k)
    events_[k].kinetic_jump = std::max(events_[k].kinetic_jump, jump);
  if (world.time() >= jump_watch_->until) jump_watch_.reset();
}

bool CrusherBreakage::check(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
  interrupted_ = false;
  watchKineticJump(*world);
  if (world->stepCount() % every_ != 0 || world->particles().size() == 0) return false;
  // The check's cost is its time but the freeze's (freeze_seconds_, timed inside).
  const auto started = std::chrono::steady_clock::now();
  const double frozen_before = freeze_seconds_;
  const bool changed = breakOverStrength(world, ctx);
  check_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() -
                    (freeze_seconds_ - frozen_before);
  return changed;
}

double CrusherBreakage::strengthOf(std::uint32_t row, std::uint64_t id, double diameter) {
  if (row >= kept_strengths_.size()) kept_strengths_.resize(row + 1);
  KeptStrength& kept = kept_strengths_[row];
  if (kept.id != id || kept.diameter != diameter)
    kept = {id, diameter, s_.strength.strength(diameter, crusher::uniformFromId(seed_, id))};
  return kept.strength;
}

bool CrusherBreakage::breakOverStrength(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
  const sim::ParticleState& p = world->particles();
  struct Broken {
    std::uint32_t row;
    double q, strength;
    Vec3 direction;
  };
  std::vector<Broken> broken;
  const std::vector<geometry::Mat3> stress = world->particleStress();
  for (std::uint32_t i = 0; i < p.size(); ++i) {
    const double d = 2 * p.radius[i];
    if (d < s_.min_diameter) continue;
    if (const auto at = deferred_until_.find(p.id[i]); at != deferred_until_.end() && world->time() < at->second)
      continue;  // its fragments found no room a moment ago
    const double q = sim::octahedralShearStress(stress[i]);
    if (!(q > 0)) continue;
    const double strength = strengthOf(i, p.id[i], d);
    if (q > strength) broken.push_back({i, q, strength, sim::principalStresses(stress[i]).minor_direction});
  }
  if (broken.empty()) return false;
  sim::Model model = world->model();
  sim::WorldState state = world->exportState();
  std::vector<bool> remove(p.size(), false);
  for (const Broken& b : broken) remove[b.row] = true;
  // The balls that bear load without the parents (a wall, or a ball that stays):
  // the local freeze holds them and lets the others move (breakage_freeze.h).
  std::vector<bool> loaded_before(p.size(), false);
  const sim::TouchingContacts touching = world->touchingContacts();
  for (const auto& [i, wall] : touching.walls) loaded_before[i] = true;
  for (const auto& [i, j] : touching.pairs) {
    if (!remove[j]) loaded_before[i] = true;
    if (!remove[i]) loaded_before[j] = true;
  }
  std::vector<bool> loaded;  // rows of `state` (withoutBalls keeps the order; no clumps)
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!remove[i]) loaded.push_back(loaded_before[i]);
  // The elastic energy the parents' contacts (with balls and walls) store now, at
  // the run's law and stiffness: what a breakage may hand back (CrowdedBound).
  double parent_energy = 0;
  addContactEnergy(parent_energy, 1.0, touching, remove);
  std::vector<std::uint32_t> run_row;  // row of `state` after the removal -> row of the run's balls
  for (std::uint32_t i = 0; i < p.size(); ++i)
    if (!remove[i]) run_row.push_back(i);
  state = sim::withoutBalls(std::move(state), remove);
  std::vector<std::uint32_t> rows;
  const std::size_t first_event = events_.size();
  // A stop request during the freeze leaves the run as it was before this check:
  // these are put back, and the world is not replaced.
  const std::uint64_t next_id_before = next_id_;
  const auto base_of_before = base_of_;
  const auto class_material_before = class_material_;
  for (const Broken& b : broken) {
    const std::uint32_t i = b.row;
    BreakageEvent e;
    e.time = world->time();
    e.parent = p.id[i];
    e.diameter = 2 * p.radius[i];
    e.q = b.q;
    e.strength = b.strength;
    e.mass = p.mass[i];
    for (const crusher::FragmentBall& f :
         crusher::splitBall(p.position[i], p.radius[i], p.mass[i], b.direction, s_.mode, s_.offsets)) {
      const int material = fragmentMaterial(model, p.material[i], 2 * f.radius);
      rows.push_back(
          sim::appendFreeSphere(state.particles, {f.position, p.velocity[i], p.omega[i], f.radius, material}, f.mass, next_id_));
      e.fragments.push_back(next_id_++);
      e.fragment_diameters.push_back(2 * f.radius);
      e.fragment_masses.push_back(f.mass);
    }
    events_.push_back(std::move(e));
  }
  loaded.resize(state.particles.size(), false);  // the fragments
  const auto freeze_start = std::chrono::steady_clock::now();
  const crusher::FreezeResult freeze =
      crusher::freezeFragments(model, state, rows, s_.freeze, ctx.threads, loaded);
  freeze_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - freeze_start).count();
  // What the freeze hands back: the run's World on the state after it (built here
  // when the positions came back; it is the run's next World if the breakage is
  // kept), and the elastic energy of the moved balls' contacts in it, at the run's
  // law and stiffness, less what the moved neighbours' contacts other than with the
  // parents held before (none for the local freeze: they touched only the parents).
  std::unique_ptr<sim::World> next;
  double handed_back = 0;
  if (!freeze.movers.empty()) {
    next = std::make_unique<sim::World>(model, std::move(state), ctx.threads);
    std::vector<bool> moved(next->particles().size(), false), moved_before(p.size(), false);
    for (const std::uint32_t m : freeze.movers) {
      moved[m] = true;
      if (m < run_row.size()) moved_before[run_row[m]] = true;  // an unbroken ball that moved
    }
    addContactEnergy(handed_back, 1.0, next->touchingContacts(), moved);  // by the positions: no step yet
    addContactEnergy(handed_back, -1.0, touching, moved_before, remove);  // a moved ball is never a parent
  }
  // A crowded freeze keeps its breakage with "break" within the bound
  // (BreakageSettings::CrowdedBound): by energy, no more elastic energy handed back
  // than the parents' contacts stored; by overlap, at most crowded_max_overlap
  // (handed back at rock stiffness an overlap f R loads a ball to q = 0.9 E_c f).
  // Otherwise, and with "defer", the parents wait.
  const bool crowded = freeze.end == crusher::FreezeEnd::Crowded;
  const bool within_bound = s_.crowded_bound == BreakageSettings::CrowdedBound::Energy
                                ? handed_back <= s_.crowded_energy_factor * parent_energy
                                : freeze.max_overlap <= s_.crowded_max_overlap;
  const bool kept = freeze.end != crusher::FreezeEnd::Interrupted &&
                    (!crowded || (s_.freeze.crowded == crusher::CrowdedOutcome::Break && within_bound));
  if (!kept) {
    interrupted_ = freeze.end == crusher::FreezeEnd::Interrupted;
    events_.resize(first_event);
    next_id_ = next_id_before;
    base_of_ = base_of_before;
    class_material_ = class_material_before;
    if (crowded) {
      // No room for the fragments: the parents stay whole for defer_time (0: until
      // the next check), then may break again where the chamber has moved on.
      Deferral d{world->time(), {}, freeze.cycles, freeze.max_overlap, parent_energy, handed_back};
      for (const Broken& b : broken) {
        d.parents.push_back(p.id[b.row]);
        deferred_until_[p.id[b.row]] = world->time() + s_.defer_time;
      }
      freeze_cycles_ += freeze.cycles;
      max_freeze_cycles_ = std::max(max_freeze_cycles_, freeze.cycles);
      deferrals_.push_back(std::move(d));
    }
    return false;
  }
  const double contact_times = static_cast<double>(freeze.cycles) * freeze.dt / freeze.contact_time;
  double jump_window = 0;  // s, kJumpWindow contact times of the heaviest fragment at rock stiffness
  for (std::size_t k = first_event; k < events_.size(); ++k) {
    events_[k].freeze_cycles = freeze.cycles;
    events_[k].freeze_end = freeze.end;
    events_[k].freeze_overlap = freeze.max_overlap;
    events_[k].freeze_contact_times = contact_times;
    events_[k].parent_energy = parent_energy;
    events_[k].handed_back_energy = handed_back;
  }
  // A kept breakage has movers today (the fragments, or every ball in "all"); were
  // one to come back with none, its state is still the run's next World.
  if (!next) next = std::make_unique<sim::World>(model, std::move(state), ctx.threads);
  const sim::ParticleState& q = next->particles();
  for (const std::uint32_t f : rows)
    jump_window = std::max(jump_window, kJumpWindow * std::numbers::pi *
                                            std::sqrt(q.mass[f] / next->model().materials[q.material[f]].kn));
  std::vector<std::uint32_t> all(p.size());
  std::iota(all.begin(), all.end(), 0u);
  jump_watch_ = JumpWatch{crusher::kineticEnergy(p, all), world->time() + jump_window, first_event, events_.size()};
  fragments_created_ += rows.size();
  ++freezes_;
  if (freeze.end == crusher::FreezeEnd::Stalled) ++freezes_stalled_;
  if (crowded) {
    ++freezes_crowded_;
    max_crowded_overlap_ = std::max(max_crowded_overlap_, freeze.max_overlap);
    max_crowded_handed_back_ = std::max(max_crowded_handed_back_, handed_back);
  }
  max_excess_ = std::max(max_excess_, handed_back - parent_energy);
  max_freeze_overlap_ = std::max(max_freeze_overlap_, freeze.max_overlap);
  freeze_cycles_ += freeze.cycles;
  max_freeze_cycles_ = std::max(max_freeze_cycles_, freeze.cycles);
  max_freeze_balls_ = std::max(max_freeze_balls_, freeze.balls);
  reach_widenings_ += static_cast<std::uint64_t>(freeze.reach_widenings);
  moved_neighbours_ += freeze.moved_neighbours;
  world = std::move(next);
  return true;
}

std::string CrusherBreakage::progress() const {
  std::ostringstream s;
  s << events_.size() << " broken";
  if (!deferrals_.empty()) s << " (" << deferrals_.size() << " deferred)";
  if (freezes_ > 0)
    s << ", freezes " << freezes_ - freezes_stalled_ - freezes_crowded_ << " converged " << freezes_stalled_
      << " stalled " << freezes_crowded_ << " crowded (overlap left <= " << max_freeze_overlap_ << ", "
      << freeze_cycles_ << " cycles)";
  return s.str();
}

nlohmann::json CrusherBreakage::report(const std::vector<double>& sieves_mm, const std::filesystem::path& out_dir) const {
  // Broken balls by the product's sieve classes (parent diameter).
  std::vector<double> edges{0};
  edges.insert(edges.end(), sieves_mm.begin(), sieves_mm.end());
  nlohmann::json by_size = nlohmann::json::array();
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const double lo = edges[k], hi = k + 1 < edges.size() ? edges[k + 1] : std::numeric_limits<double>::infinity();
    std::size_t n = 0;
    for (const BreakageEvent& e : events_)
      if (e.diameter * 1e3 >= lo && e.diameter * 1e3 < hi) ++n;
    by_size.push_back({{"from_mm", lo}, {"to_mm", detail::finiteOrNull(hi)},
                       {"broken", n}});
  }
  std::ostringstream csv;
  csv.precision(17);
  csv << "time_s,parent_id,diameter_mm,q_MPa,strength_MPa,mode,fragment_ids,freeze_cycles,freeze_end,"
         "freeze_overlap_fraction,freeze_contact_times,kinetic_jump_J,parent_energy_J,handed_back_energy_J\n";
  for (const BreakageEvent& e : events_) {
    csv << e.time << ',' << e.parent << ',' << e.diameter * 1e3 << ',' << e.q * 1e-6 << ',' << e.strength * 1e-6 << ','
        << crusher::modeName(s_.mode) << ',';
    for (std::size_t k = 0; k < e.fragments.size(); ++k) csv << (k ? ";" : "") << e.fragments[k];
    csv << ',' << e.freeze_cycles << ',' << crusher::freezeEndName(e.freeze_end) << ',' << e.freeze_overlap << ','
        << e.freeze_contact_times << ',' << e.kinetic_jump << ',' << e.parent_energy << ','
        << e.handed_back_energy << '\n';
  }
  double max_jump = 0, max_crowded_jump = 0;
  for (const BreakageEvent& e : events_) {
    max_jump = std::max(max_jump, e.kinetic_jump);
    if (e.freeze_end == crusher::FreezeEnd::Crowded) max_crowded_jump = std::max(max_crowded_jump, e.kinetic_jump);
  }
  detail::writeAtomically(out_dir / "breakage.csv", csv.str());
  nlohmann::json b;
  b["events"] = events_.size();
  b["fragments_created"] = fragments_created_;
  b["broken_by_size"] = by_size;
  b["freezes"] = freezes_;
  b["freeze_cycles"] = freeze_cycles_;
  b["max_freeze_cycles"] = max_freeze_cycles_;
  b["freezes_converged"] = freezes_ - freezes_stalled_ - freezes_crowded_;
  b["freezes_stalled"] = freezes_stalled_;
  b["freezes_crowded"] = freezes_crowded_;
  b["max_freeze_overlap_fraction"] = max_freeze_overlap_;
  b["max_crowded_overlap_fraction"] = max_crowded_overlap_;
  b["max_kinetic_jump_J"] = max_jump;
  b["max_crowded_kinetic_jump_J"] = max_crowded_jump;
  b["freeze_crowded"] = crusher::crowdedOutcomeName(s_.freeze.crowded);
  b["freeze_crowded_max_overlap"] = s_.crowded_max_overlap;
  b["freeze_crowded_bound"] = crowdedBoundName(s_.crowded_bound);
  b["freeze_crowded_energy_factor"] = s_.crowded_energy_factor;
  // J: the most a kept crowded freeze handed back, and over every kept freeze the
  // largest excess of what it handed back over what its parents stored (<= 0: no
  // elastic energy created by any breakage).
  b["max_crowded_handed_back_energy_J"] = max_crowded_handed_back_;
  b["max_handed_back_excess_J"] = freezes_ > 0 ? nlohmann::json(max_excess_) : nlohmann::json(nullptr);
  b["freeze_max_contact_times"] = s_.freeze.max_contact_times;
  b["freeze_jam_contact_times"] = s_.freeze.jam_contact_times;
  b["freeze_scope"] = crusher::freezeScopeName(s_.freeze.scope);
  b["max_freeze_balls"] = max_freeze_balls_;
  b["freeze_reach_widenings"] = reach_widenings_;
  b["freeze_moved_neighbours"] = moved_neighbours_;
  nlohmann::json deferred = nlohmann::json::array();
  for (const Deferral& d : deferrals_)
    deferred.push_back({{"time_s", d.time}, {"parents", d.parents}, {"freeze_cycles", d.cycles},
                        {"overlap_fraction", d.overlap}, {"parent_energy_J", d.parent_energy},
                        {"handed_back_energy_J", d.handed_back_energy}});
  b["deferred"] = deferred;
  b["defer_time_s"] = s_.defer_time;
  b["check_interval_s"] = check_interval_;
  b["start"] = breakageStartName(s_.start);
  b["check_interval_from"] = s_.check_interval > 0 ? "experiment.breakage.check_interval"
                                                   : "automatic: a quarter of the shortest contact time of a ball of "
                                                     "min_diameter on a wall";
  b["mode"] = crusher::modeName(s_.mode);
  b["offsets"] = s_.offsets;
  b["strength"] = {{"q_ref_MPa", s_.strength.q_ref * 1e-6}, {"d_ref_mm", s_.strength.d_ref * 1e3},
                   {"size_exponent", s_.strength.size_exponent}, {"weibull_modulus", s_.strength.weibull_modulus},
                   {"min_diameter_mm", s_.min_diameter * 1e3}};
  b["method"] = "every check_interval a ball of at least min_diameter whose octahedral shear stress q exceeds its "
                "strength q0(d) (-ln U)^(1/m) (U from the seed and its id) is replaced by fragments inside it along "
                "its minor principal stress; a freeze (own clock, walls held; scope \"local\": the fragments among "
                "their held neighbours, \"all\": every ball) eases them apart (breakage.csv)";
  return b;
}

}  // namespace rocklab::experiments
