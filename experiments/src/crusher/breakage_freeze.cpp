#include "crusher/breakage_freeze.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "rocklab/experiments/run.h"
#include "rocklab/sim/timestep.h"
#include "rocklab/sim/wall_motion.h"

namespace rocklab::experiments::crusher {

namespace {

using geometry::Vec3;

/// The wall where its motion has it at time t, without the motion; a wall not
/// there at t is never active.
sim::Wall heldWall(const sim::Wall& moving, double t) {
  sim::Wall w = moving;
  const sim::WallPose pose = sim::wallPoseAt(moving.motion, t);
  w.point = pose.place(moving.point);
  w.normal = pose.rotation * moving.normal;
  for (Vec3& v : w.vertices) v = pose.place(v);
  for (Vec3& v : w.mesh.vertices) v = pose.place(v);
  w.motion = sim::WallMotion{};
  w.active_from = -std::numeric_limits<double>::infinity();
  w.active_until = moving.activeAt(t) ? std::numeric_limits<double>::infinity() : std::numeric_limits<double>::lowest();
  return w;
}

/// §g.6 steps 2-6 as a model: held walls, no gravity, no dashpots, local damping,
/// the fragments on soft copies of their materials (rows of `material` changed).
sim::Model freezeModel(const sim::Model& run, double t, std::vector<std::int32_t>& material,
                       const std::vector<std::uint32_t>& fragments, const FreezeSettings& s) {
  sim::Model m = run;
  for (sim::Wall& w : m.walls) w = heldWall(w, t);
  m.gravity = Vec3::Zero();
  m.gravity_changes.clear();
  m.contact.damping_normal = m.contact.damping_shear = 0.0;
  m.contact.local_damping = s.local_damping;
  m.timestep.dt = 0.0;  // its own automatic step
  m.timestep.allow_unsafe = false;
  m.relaxation.steps = 0;
  // The fragments overlap by design: the overlap watchdog is off; the energy one
  // stays (the freeze only dissipates); the network check costs and finds nothing.
  m.watchdog.max_overlap_fraction = std::numeric_limits<double>::infinity();
  m.watchdog.network_iterations = 0;
  std::map<std::int32_t, std::int32_t> soft;  // run material -> its soft copy
  for (const std::uint32_t f : fragments) {
    auto [it, added] = soft.try_emplace(material[f], static_cast<std::int32_t>(m.materials.size()));
    if (added) {
      sim::Material copy = run.materials[material[f]];
      copy.name += " (freeze)";
      copy.kn = copy.ks = s.stiffness;
      m.materials.push_back(copy);
    }
    material[f] = it->second;
  }
  return m;
}

/// The largest overlap of any ball flagged in `is_mover` with a wall, over its radius. The walls
/// are held, so a fragment pressed into one by its neighbours can stay there; handed
/// back, that overlap would be at the wall's stiffness (1e13 N/m in series with the
/// ball's) and break it again at the next check.
double wallOverlapFraction(const sim::World& world, const std::vector<bool>& is_mover) {
  const sim::ParticleState& p = world.particles();
  const sim::TouchingContacts t = world.touchingContacts();
  double worst = 0;
  for (std::size_t k = 0; k < t.walls.size(); ++k)
    if (is_mover[t.walls[k].first]) worst = std::max(worst, t.wall_overlap[k] / p.radius[t.walls[k].first]);
  return worst;
}

/// Whether the largest overlap has stopped falling: the samples (cycle, overlap)
/// of the last `window` cycles, the oldest at or before its start.
class OverlapStall {
 public:
  OverlapStall(std::uint64_t window, double tolerance) : window_(window), tolerance_(tolerance) {}
  /// Adds the sample of `cycle`; true when the window is full and no sample in it
  /// fell below (1 - tolerance) of the first.
  bool stalled(std::uint64_t cycle, double overlap) {
    if (window_ == 0) return false;
    samples_.push_back({cycle, overlap});
    while (samples_.size() >= 2 && samples_[1].cycle + window_ <= cycle) samples_.pop_front();
    if (samples_.front().cycle + window_ > cycle) return false;
    const double floor = (1 - tolerance_) * samples_.front().overlap;
    return std::all_of(samples_.begin(), samples_.end(), [&](const Sample& s) { return s.overlap >= floor; });
  }

 private:
  struct Sample {
    std::uint64_t cycle;
    double overlap;
  };
  std::uint64_t window_;
  double tolerance_;
  std::deque<Sample> samples_;
};

}  // namespace

double kineticEnergy(const sim::ParticleState& p, const std::vector<std::uint32_t>& rows) {
  double e = 0;
  for (const std::uint32_t i : rows)
    e += 0.5 * p.mass[i] * p.velocity[i].squaredNorm() + 0.5 * p.omega[i].squaredNorm() / p.inv_inertia[i];
  return e;
}

const char* crowdedOutcomeName(CrowdedOutcome outcome) {
  switch (outcome) {
    case CrowdedOutcome::Defer: return "defer";
    case CrowdedOutcome::Stop: return "stop";
    case CrowdedOutcome::Break: break;
  }
  return "break";
}

const char* freezeEndName(FreezeEnd end) {
  switch (end) {
    case FreezeEnd::Stalled: return "stalled";
    case FreezeEnd::Interrupted: return "interrupted";
    case FreezeEnd::Crowded: return "crowded";
    case FreezeEnd::Converged: break;
  }
  return "converged";
}

bool BallCells::build(const sim::ParticleState& p) {
  cell_of_.clear();
  first_.assign(1, 0);
  by_cell_.clear();
  if (p.size() == 0) return true;
  lo_ = hi_ = p.position[0];
  for (const Vec3& x : p.position) {
    lo_ = lo_.cwiseMin(x);
    hi_ = hi_.cwiseMax(x);
  }
  if (!(hi_ - lo_).allFinite()) return false;
  // Cells at least as wide as the largest pair reach: a ball touching f lies in one
  // of the 27 cells around f's (the margin keeps a pair that only round-off
  // separates on the inside). Wider cells where the balls' box would need too many.
  const double r_max = *std::max_element(p.radius.begin(), p.radius.end());
  cell_ = r_max > 0 ? 2.0 * r_max * (1 + 1e-9) : 1.0;
  for (;; cell_ *= 2) {
    for (int a = 0; a < 3; ++a) dims_[a] = static_cast<std::size_t>((hi_[a] - lo_[a]) / cell_) + 1;
    if (static_cast<double>(dims_[0]) * static_cast<double>(dims_[1]) * static_cast<double>(dims_[2]) <=
        4.0 * static_cast<double>(p.size()) + 64)
      break;
  }
  // The balls by cell: a counting sort, in ball order within a cell.
  cell_of_.resize(p.size());
  first_.assign(dims_[0] * dims_[1] * dims_[2] + 1, 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::array<std::size_t, 3> c = cellOf(p.position[i]);
    cell_of_[i] = index(c[0], c[1], c[2]);
    ++first_[cell_of_[i] + 1];
  }
  for (std::size_t k = 1; k < first_.size(); ++k) first_[k] += first_[k - 1];
  by_cell_.resize(p.size());
  fill_.assign(first_.begin(), first_.end() - 1);
  for (std::size_t i = 0; i < p.size(); ++i) by_cell_[fill_[cell_of_[i]]++] = static_cast<std::uint32_t>(i);
  return true;
}

FragmentOverlaps fragmentOverlaps(const sim::Model& model, const sim::ParticleState& p,
                                  const std::vector<std::uint32_t>& fragments) {
  FragmentOverlaps o;
  if (fragments.empty()) return o;
  // The balls that can touch a fragment, from a grid of cells one largest diameter
  // wide (every ball against every fragment took four fifths of a run's time once a
  // weak feed had broken into thousands of balls and hundreds of fragments froze).
  BallCells cells;
  if (!cells.build(p)) return {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  std::vector<bool> is_fragment(p.size(), false);
  for (const std::uint32_t f : fragments) is_fragment[f] = true;
  std::vector<std::pair<std::uint32_t, double>> touching;  // (ball, overlap) of one fragment
  for (const std::uint32_t f : fragments) {
    touching.clear();
    cells.forEachNear(p.position[f], [&](std::uint32_t j) {
      if (j == f || (is_fragment[j] && j < f)) return;  // each fragment pair once
      const double overlap = p.radius[f] + p.radius[j] - (p.position[f] - p.position[j]).norm();
      if (overlap > 0) touching.emplace_back(j, overlap);
    });
    // In ball order, the few that touch: the sums as over every ball.
    std::sort(touching.begin(), touching.end());
    for (const auto& [j, overlap] : touching) {
      o.max_fraction = std::max(o.max_fraction, overlap / std::min(p.radius[f], p.radius[j]));
      const double kf = model.materials[p.material[f]].kn, kj = model.materials[p.material[j]].kn;
      o.energy += 0.5 * kf * kj / (kf + kj) * overlap * overlap;
    }
  }
  return o;
}

double LargestOverlap::operator()(const sim::ParticleState& p, const std::vector<std::uint32_t>& movers) {
  if (movers.empty()) return 0.0;
  // A ball off to infinity (or NaN) has no cell; nothing the engine hands over has
  // one, and were it to, "no room" is the safe answer (the freeze does not end as
  // converged).
  if (!cells_.build(p)) return std::numeric_limits<double>::infinity();
  double worst = 0;
  for (const std::uint32_t f : movers)
    cells_.forEachNear(p.position[f], [&](std::uint32_t j) {
      if (j == f) return;
      // fragmentOverlaps' expression, so the largest is the same to the bit.
      const double overlap = p.radius[f] + p.radius[j] - (p.position[f] - p.position[j]).norm();
      if (overlap > 0) worst = std::max(worst, overlap / std::min(p.radius[f], p.radius[j]));
    });
  return worst;
}

namespace {

/// One freeze of `frozen` (a copy of the run's balls, or of the local ones): the
/// fragments at `density`, the balls flagged in `held` at held_density, all at
/// rest, cycled until a way out. `after` receives the state at the end when the
/// freeze converged or stalled, or was crowded with crowded "break".
FreezeResult runFreeze(const sim::Model& model, sim::WorldState frozen,
                       const std::vector<std::uint32_t>& fragments, const std::vector<bool>& held,
                       const FreezeSettings& s, int threads, double t_break,
                       sim::WorldState& after) {
  sim::ParticleState& p = frozen.particles;
  const sim::Model m = freezeModel(model, frozen.time, p.material, fragments, s);
  std::vector<std::uint32_t> moving;  // the balls whose kinetic energy counts
  for (std::uint32_t i = 0; i < p.size(); ++i) {
    const bool is_held = !held.empty() && held[i];
    sim::setFreeSphereMass(p, i,
                           sim::sphereMass(is_held ? s.held_density : s.density, p.radius[i]));
    p.velocity[i] = p.omega[i] = Vec3::Zero();
    if (!is_held) moving.push_back(i);
  }
  FreezeResult result;
  result.balls = p.size();
  result.dt = sim::auditTimestep(m, p).automatic;
  frozen.time = 0.0;  // the freeze's own clock (time = step x dt)
  frozen.step = 0;
  frozen.dt = result.dt;
  frozen.half_kick_pending = true;
  sim::World world(m, std::move(frozen), threads);
  result.artificial_energy = fragmentOverlaps(m, world.particles(), fragments).energy;
  double heaviest = 0;  // kg, at the freeze density
  for (const std::uint32_t f : fragments) heaviest = std::max(heaviest, world.particles().mass[f]);
  const double time_scale = std::sqrt(heaviest / s.stiffness);  // s, the slowest mover's sqrt(m/k)
  if (s.stall_window > 0)
    result.stall_window_cycles =
        std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(s.stall_window * time_scale / result.dt)));
  // The crowded cap in the movers' own time, bounded by the absolute one (head of breakage_freeze.h).
  result.contact_time = std::numbers::pi * time_scale;
  result.cap_cycles = static_cast<std::uint64_t>(s.max_cycles);
  if (s.max_contact_times > 0)
    result.cap_cycles = std::clamp<std::uint64_t>(
        static_cast<std::uint64_t>(std::ceil(s.max_contact_times * result.contact_time / result.dt)), 1,
        result.cap_cycles);
  if (s.jam_contact_times > 0)
    result.jam_window_cycles = std::max<std::uint64_t>(
        1, static_cast<std::uint64_t>(std::ceil(s.jam_contact_times * result.contact_time / result.dt)));
  // At the fragments' own step ("local") the window is a few hundred cycles: the
  // criteria are looked at often enough to see it.
  std::uint64_t check = static_cast<std::uint64_t>(s.check_cycles);
  if (result.stall_window_cycles > 0)
    check = std::clamp<std::uint64_t>(result.stall_window_cycles / 4, 1, check);
  OverlapStall stall(result.stall_window_cycles, s.stall_tolerance);
  OverlapStall jam(result.jam_window_cycles, s.stall_tolerance);
  LargestOverlap largest_overlap;
  std::vector<bool> is_fragment(world.particles().size(), false);  // for the wall overlaps, every check
  for (const std::uint32_t f : fragments) is_fragment[f] = true;
  for (;;) {
    if (result.cycles % check == 0) {
      if (stopRequested()) {
        result.end = FreezeEnd::Interrupted;
        return result;
      }
      // The contacts (with the walls' overlaps) are known after the first step.
      if (result.cycles == 0) {
        world.step();
        ++result.cycles;
        continue;
      }
      result.max_overlap =
          std::max(largest_overlap(world.particles(), fragments), wallOverlapFraction(world, is_fragment));
      result.kinetic_energy = kineticEnergy(world.particles(), moving);
      const bool at_rest = result.kinetic_energy <= s.kinetic_fraction * result.artificial_energy;
      const bool stalled = stall.stalled(result.cycles, result.max_overlap);  // records the sample
      const bool jammed = jam.stalled(result.cycles, result.max_overlap);     // likewise
      // The overlap criterion first: a freeze that can converge ends as converged.
      if (at_rest && result.max_overlap <= s.overlap_fraction) break;
      if (at_rest && stalled && result.max_overlap <= s.stall_max_overlap) {
        result.end = FreezeEnd::Stalled;
        break;
      }
      result.jammed = at_rest && jammed && result.cycles < result.cap_cycles;
      if (result.cycles >= result.cap_cycles || (result.jammed && s.crowded != CrowdedOutcome::Stop)) {
        if (s.crowded != CrowdedOutcome::Stop) {
          result.end = FreezeEnd::Crowded;
          if (s.crowded == CrowdedOutcome::Defer) return result;
          break;  // "break": the fragments go back where they are
        }
        std::ostringstream msg;
        msg << "experiment.breakage: the freeze after breakage at t = " << t_break
            << " s did not end within " << result.cap_cycles << " cycles (freeze_max_contact_times = "
            << s.max_contact_times << " contact times of " << result.contact_time << " s at the freeze step "
            << result.dt << " s, at most freeze_max_cycles = " << s.max_cycles
            << "): the largest fragment overlap is " << result.max_overlap
            << " of the smaller radius (freeze_overlap_fraction = " << s.overlap_fraction
            << ") and the kinetic energy " << result.kinetic_energy << " J is "
            << result.kinetic_energy / result.artificial_energy << " of the fragments' initial "
            << result.artificial_energy << " J (freeze_kinetic_fraction = " << s.kinetic_fraction
            << ") and it has not stalled (freeze_stall_tolerance = " << s.stall_tolerance
            << " over freeze_stall_window = " << s.stall_window << " fragment time scales, "
            << result.stall_window_cycles
            << " cycles, at an overlap of at most freeze_stall_max_overlap = "
            << s.stall_max_overlap
            << "); raise freeze_max_contact_times or freeze_max_cycles, relax the criteria, or set "
               "freeze_crowded = \"break\" or \"defer\"";
        throw std::runtime_error(msg.str());
      }
    }
    world.step();
    ++result.cycles;
  }
  after = world.exportState();
  return result;
}

/// Whether the positions a freeze reached go back into the run: converged,
/// stalled, or crowded with crowded "break".
bool handsBack(FreezeEnd end, CrowdedOutcome crowded) {
  return end == FreezeEnd::Converged || end == FreezeEnd::Stalled ||
         (end == FreezeEnd::Crowded && crowded == CrowdedOutcome::Break);
}

/// The balls within `reach` (m, surface to surface) of any of `fragments`, these included.
std::vector<bool> localBalls(const sim::ParticleState& p,
                             const std::vector<std::uint32_t>& fragments, double reach) {
  std::vector<bool> local(p.size(), false);
  for (const std::uint32_t f : fragments) local[f] = true;
  for (std::uint32_t j = 0; j < p.size(); ++j)
    for (const std::uint32_t f : fragments)
      if (!local[j] && (p.position[j] - p.position[f]).norm() - p.radius[j] - p.radius[f] <= reach)
        local[j] = true;
  return local;
}

/// Whether a fragment (position in `moved`) overlaps a ball not flagged in `local`.
bool touchesOutside(const sim::ParticleState& p, const std::vector<std::uint32_t>& fragments,
                    const std::vector<Vec3>& moved, const std::vector<bool>& local) {
  for (std::size_t k = 0; k < fragments.size(); ++k)
    for (std::uint32_t j = 0; j < p.size(); ++j)
      if (!local[j] && (p.position[j] - moved[k]).norm() < p.radius[j] + p.radius[fragments[k]])
        return true;
  return false;
}

}  // namespace

const char* freezeScopeName(FreezeScope scope) {
  return scope == FreezeScope::All ? "all" : "local";
}

FreezeResult freezeFragments(const sim::Model& model, sim::WorldState& state,
                             const std::vector<std::uint32_t>& fragments, const FreezeSettings& s,
                             int threads, const std::vector<bool>& loaded) {
  const sim::ParticleState& p = state.particles;
  if (s.scope == FreezeScope::All || p.clumps.size() > 0) {  // withoutBalls would take clumps whole
    sim::WorldState after;
    const FreezeResult result =
        runFreeze(model, state, fragments, {}, s, threads, state.time, after);
    FreezeResult all = result;
    if (handsBack(result.end, s.crowded)) {
      state.particles.position = after.particles.position;
      state.pair_history = after.pair_history;
      state.wall_history = after.wall_history;
      all.movers.resize(state.particles.size());
      std::iota(all.movers.begin(), all.movers.end(), 0u);
    }
    return all;
  }
  if (!loaded.empty() && loaded.size() != p.size())
    throw std::invalid_argument("freezeFragments: one `loaded` flag per ball is needed");
  std::vector<bool> is_fragment(p.size(), false);
  for (const std::uint32_t f : fragments) is_fragment[f] = true;
  double largest = 0;  // m, the largest fragment's diameter
  for (const std::uint32_t f : fragments) largest = std::max(largest, 2 * p.radius[f]);
  FreezeResult total;
  for (double reach = s.local_reach * largest;; reach *= 2) {
    const std::vector<bool> local = localBalls(p, fragments, reach);
    // The balls that move: the fragments, and the neighbours that bore no load
    // (they touched nothing but the parents), which the fragments push aside as
    // they would with every ball in. The loaded ones are held.
    std::vector<std::uint32_t> movers = fragments;
    for (std::uint32_t i = 0; i < p.size(); ++i)
      if (local[i] && !is_fragment[i] && !loaded.empty() && !loaded[i]) movers.push_back(i);
    std::vector<std::uint32_t> full_row;  // local row -> the run's row (withoutBalls keeps the order)
    std::vector<std::uint32_t> local_row(p.size(), UINT32_MAX);
    for (std::uint32_t i = 0; i < p.size(); ++i)
      if (local[i]) {
        local_row[i] = static_cast<std::uint32_t>(full_row.size());
        full_row.push_back(i);
      }
    std::vector<bool> outside(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) outside[i] = !local[i];
    std::vector<std::uint32_t> local_movers;
    std::vector<bool> held(full_row.size(), true);
    for (const std::uint32_t m : movers) {
      local_movers.push_back(local_row[m]);
      held[local_row[m]] = false;
    }
    sim::WorldState after;
    const FreezeResult result = runFreeze(model, sim::withoutBalls(state, outside), local_movers,
                                          held, s, threads, state.time, after);
    const std::uint64_t cycles = total.cycles + result.cycles;
    const int widenings = total.reach_widenings;
    total = result;
    total.cycles = cycles;
    total.reach_widenings = widenings;
    total.moved_neighbours = movers.size() - fragments.size();
    if (!handsBack(result.end, s.crowded)) return total;
    std::vector<Vec3> moved;
    for (const std::uint32_t m : local_movers) moved.push_back(after.particles.position[m]);
    if (touchesOutside(p, movers, moved, local) && full_row.size() < p.size()) {
      ++total.reach_widenings;  // it travelled beyond the reach: again, wider
      continue;
    }
    std::vector<bool> is_mover(p.size(), false);
    for (std::size_t k = 0; k < movers.size(); ++k) {
      is_mover[movers[k]] = true;
      state.particles.position[movers[k]] = moved[k];
    }
    // History: the held balls keep theirs, the movers' comes from the freeze.
    std::vector<sim::PairHistory> pairs;
    for (const sim::PairHistory& h : state.pair_history)
      if (!is_mover[h.i] && !is_mover[h.j]) pairs.push_back(h);
    for (sim::PairHistory h : after.pair_history) {
      h.i = full_row[h.i];
      h.j = full_row[h.j];
      if (is_mover[h.i] || is_mover[h.j]) pairs.push_back(h);
    }
    std::vector<sim::WallHistory> walls;
    for (const sim::WallHistory& h : state.wall_history)
      if (!is_mover[h.particle]) walls.push_back(h);
    for (sim::WallHistory h : after.wall_history) {
      h.particle = full_row[h.particle];
      if (is_mover[h.particle]) walls.push_back(h);
    }
    state.pair_history = std::move(pairs);
    state.wall_history = std::move(walls);
    total.movers = movers;
    return total;
  }
}

}  // namespace rocklab::experiments::crusher
