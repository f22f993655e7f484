#include "rocklab/sim/world.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>

#include "contact_kernel.h"
#include "contact_spectrum.h"
#include "neighbor_list.h"
#include "rigid_body.h"
#include "rocklab/sim/wall_motion.h"
#include "wall_runtime.h"

namespace rocklab::sim {

using detail::PairProps;

namespace {

// Reduction of the per-step checks; merged in a thread-independent way (max, or).
struct StepChecks {
  double max_disp2 = 0.0;        // m^2, largest squared displacement since the last rebuild
  bool non_finite = false;
  double worst_overlap = 0.0;    // overlap / smaller radius
  std::uint64_t worst_key = 0;   // (i << 32 | j) of that contact; j = kWallBit | wall for walls
};
constexpr std::uint64_t kWallBit = 1ull << 31;

void mergeWorst(StepChecks& into, double ratio, std::uint64_t key) {
  if (ratio > into.worst_overlap || (ratio == into.worst_overlap && ratio > 0 && key < into.worst_key)) {
    into.worst_overlap = ratio;
    into.worst_key = key;
  }
}

/// Folds one thread's checks into the step's (call inside `omp critical`).
void mergeChecks(StepChecks& into, const StepChecks& from) {
  mergeWorst(into, from.worst_overlap, from.worst_key);
  into.max_disp2 = std::max(into.max_disp2, from.max_disp2);
  into.non_finite = into.non_finite || from.non_finite;
}

std::string fmtNum(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

}  // namespace

struct World::Impl {
  Model model;
  ParticleState p;
  int threads = 1;
  double time = 0.0;
  std::uint64_t step = 0;
  double dt = 0.0;
  bool half_kick_pending = true;
  Vec3 gravity = Vec3::Zero();
  TimestepAudit audit;
  WorldStats stats;
  double skin = 0.0;

  // Material-pair constants: ball_ball[a * nm + b], ball_wall[ball * nm + wall].
  std::vector<PairProps> ball_ball, ball_wall;
  std::size_t nm = 0;
  std::vector<detail::WallRuntime> walls;

  // Ball–ball pairs (canonical CSR) and their per-pair data.
  detail::NeighborFinder finder;
  detail::PairList pairs;
  std::vector<Vec3> pair_shear;      // [pairs] N, shear spring force on i (history)
  std::vector<std::uint8_t> pair_touch;  // [pairs] 1 when touching at this step
  // Ranges of balls per thread, and the slots of pairs that cross two ranges.
  struct CrossSlot {
    Vec3 fi, ti, fj, tj;  // N, N m on the first and the second ball
  };
  static constexpr std::uint32_t kNotCross = 0xffffffffu;
  std::vector<std::uint32_t> range_begin;  // [team+1]
  std::vector<std::uint32_t> cross_index;  // [pairs] slot, or kNotCross
  std::vector<CrossSlot> cross;
  // Ball–wall candidates in rows by ball.
  std::vector<std::uint32_t> wall_offset;  // [n+1]
  std::vector<std::uint32_t> wall_index;   // [k]
  std::vector<Vec3> wall_shear;            // [k] N on the ball
  std::vector<std::uint8_t> wall_touch;    // [k]
  // Relaxation of initial overlaps (Model::relaxation); empty when off or done.
  std::vector<double> pair_relax;  // [pairs] m, initial overlap of the pair (offset at factor 1)
  std::vector<double> wall_relax;  // [k] m, the same for ball–wall candidates
  bool relax_pending = false;      // offsets still to be taken at the first step
  double relax_factor = 0.0;       // offset / initial overlap at this step (1 -> 0, smoothstep)
  bool relaxing() const { return !pair_relax.empty(); }
  // Per-ball force and torque accumulators (contacts only).
  std::vector<Vec3> acc_force, acc_torque;
  // Observation buffers (filled only on observed steps).
  std::vector<Vec3> obs_velocity, obs_omega;
  std::vector<Vec3> obs_clump_velocity, obs_clump_omega;
  bool has_clumps = false;
  bool isMember(std::size_t i) const { return has_clumps && p.clump[i] >= 0; }
  // Skin bookkeeping.
  std::vector<Vec3> ref_position;
  bool need_rebuild = true;
  double last_max_disp2 = 0.0;
  // Watchdog energy reference.
  bool energy_ref_valid = false;
  double energy_ref = 0.0, energy_scale = 0.0;
  // Work done on each ball by moving walls since the energy reference (J), net
  // and gross (sum of |dW|); empty when no wall moves. Per ball, so the sums do
  // not depend on the number of threads.
  std::vector<double> wall_work, wall_work_gross;
  std::vector<std::uint8_t> wall_moving;  // [walls] 1 when the wall has a prescribed motion
  // Highest frequency of the contact network (step check), kept between checks.
  detail::SpectrumEstimate spectrum;
  detail::ContactNetwork network;  // rebuilt at every check (buffers reused)

  // Below this many balls per thread a second thread does not pay: a step of a
  // few thousand balls takes tens of microseconds, and waking the team, the
  // barrier and the cross-range pairs cost as much (measured: the 1500-ball demo
  // ran 1.65x slower on 2 threads, while 2000 lattice balls ran 1.7x faster, and
  // 16000 balls 1.5-1.9x faster). Results are bitwise the same whatever the team.
  static constexpr std::size_t kMinBallsPerThread = 2500;
  int teamSize() const {
    const auto useful = static_cast<int>(p.size() / kMinBallsPerThread);
    return std::max(1, std::min(threads, useful));
  }
  void initialise(int requested_threads);
  void buildPairProps();
  void prepareStage();
  void rebuildNeighbours();
  template <class Law>
  bool evaluatePair(std::size_t i, std::uint32_t k, Vec3& fi, Vec3& ti, Vec3& fj, Vec3& tj, StepChecks& c);
  template <class Law> void addWallForces(std::size_t i, Vec3& f, Vec3& t, StepChecks& c);
  template <class Law> void forcePass(bool integrate_now, double h, StepChecks& merged);
  void assignRanges();
  void integrate(std::size_t i, const Vec3& f_contact, const Vec3& torque, double h, StepChecks& c);
  void clumpLoad(std::size_t c, Vec3& force, Vec3& torque) const;
  void integrateClumps(double h, StepChecks& merged);
  void placeMembers(std::size_t c);
  template <class Law> Energy energy(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const;
  Energy energyAny(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const;
  void checkOverlap(const StepChecks& checks) const;
  void checkFinite() const;
  void checkEnergy(const Energy& e);
  template <class Law> void buildContactNetwork(detail::ContactNetwork& net) const;
  void checkNetworkStep();
  void startRelaxation();
  void updateRelaxation();
  bool energyCheckApplies() const;
  std::string stepAdvice() const;
  void doStep(const std::function<void(const Snapshot&)>& observer);
};

// ---------------------------------------------------------------------------
// Set-up

std::string validateModel(const Model& model, const std::vector<SphereSpec>& spheres,
                          const std::vector<ClumpSpec>& clumps) {
  std::ostringstream e;
  if (model.materials.empty()) return "no materials defined";
  if (model.relaxation.steps < 0) return "relaxation.steps must be >= 0";
  for (std::size_t k = 0; k < model.materials.size(); ++k) {
    const Material& m = model.materials[k];
    const std::string where = "material '" + m.name + "'";
    if (!(m.density > 0)) return where + ": density must be > 0 kg/m^3";
    if (!(m.friction >= 0)) return where + ": friction must be >= 0";
    if (model.contact.law == ContactLaw::Linear && !(m.kn > 0 && m.ks >= 0))
      return where + ": the linear law needs kn > 0 and ks >= 0 N/m";
    if (model.contact.law == ContactLaw::HertzMindlin &&
        !(m.shear_modulus > 0 && m.poisson > -1 && m.poisson < 0.5))
      return where + ": Hertz–Mindlin needs shear_modulus > 0 Pa and -1 < poisson < 0.5";
  }
  const auto nm = static_cast<int>(model.materials.size());
  for (const Wall& w : model.walls) {
    const std::string where = "wall '" + w.name + "'";
    if (w.material < 0 || w.material >= nm) return where + ": unknown material";
    if (w.shape == WallShape::Plane) {
      if (!(w.normal.norm() > 0)) return where + ": normal must not be zero";
      if (!w.motion.angular_velocity.isZero(0))
        return where + ": an infinite plane cannot rotate; use a polygon";
    }
    if (w.shape == WallShape::Polygon) {
      if (w.vertices.size() < 3) return where + ": a polygon needs at least 3 vertices";
      const Vec3 nrm = polygonNormal(w.vertices);
      if (!(nrm.norm() > 0)) return where + ": the first three vertices are collinear";
      const double scale = (w.vertices[1] - w.vertices[0]).norm();
      for (const Vec3& v : w.vertices)
        if (std::abs((v - w.vertices[0]).dot(nrm)) > 1e-9 * std::max(1.0, scale))
          return where + ": the vertices are not in one plane";
    }
    if (w.shape == WallShape::Mesh) {
      const std::string msg = w.mesh.validate();
      if (!msg.empty()) return where + ": " + msg;
    }
    if (!(w.active_until > w.active_from)) return where + ": active_until must be after active_from";
  }
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const SphereSpec& s = spheres[i];
    if (!(s.radius > 0)) {
      e << "sphere " << i << ": radius must be > 0 m";
      return e.str();
    }
    if (s.material < 0 || s.material >= nm) {
      e << "sphere " << i << ": unknown material index " << s.material;
      return e.str();
    }
    if (!s.position.allFinite() || !s.velocity.allFinite() || !s.omega.allFinite()) {
      e << "sphere " << i << ": position, velocity and omega must be finite";
      return e.str();
    }
  }
  for (std::size_t c = 0; c < clumps.size(); ++c) {
    const ClumpSpec& k = clumps[c];
    e.str("");
    e << "clump " << c << ": ";
    if (k.members.empty()) return e.str() + "has no member spheres";
    if (!(k.mass > 0)) return e.str() + "mass must be > 0 kg";
    if (!(k.principal_inertia.minCoeff() > 0) || !k.principal_inertia.allFinite())
      return e.str() + "principal inertia must be > 0 kg m^2";
    if (k.material < 0 || k.material >= nm) return e.str() + "unknown material index";
    if (!k.position.allFinite() || !k.velocity.allFinite() || !k.omega.allFinite() ||
        !k.orientation.coeffs().allFinite() || std::abs(k.orientation.norm() - 1.0) > 1e-9)
      return e.str() + "position, velocity and omega must be finite and the orientation a unit quaternion";
    for (const geometry::Sphere& m : k.members)
      if (!(m.radius > 0) || !m.centre.allFinite()) return e.str() + "member radius must be > 0 m";
  }
  return {};
}

World::World(Model model, const std::vector<SphereSpec>& spheres, int threads)
    : World(std::move(model), spheres, {}, threads) {}

World::World(Model model, const std::vector<SphereSpec>& spheres, const std::vector<ClumpSpec>& clumps,
             int threads)
    : impl_(std::make_unique<Impl>()) {
  const std::string msg = validateModel(model, spheres, clumps);
  if (!msg.empty()) throw std::invalid_argument(msg);
  Impl& w = *impl_;
  w.model = std::move(model);
  ParticleState& p = w.p;
  std::size_t members = 0;
  for (const ClumpSpec& c : clumps) members += c.members.size();
  const std::size_t n = spheres.size() + members;
  p.position.resize(n);
  p.velocity.resize(n);
  p.omega.resize(n);
  p.radius.resize(n);
  p.inv_mass.resize(n);
  p.inv_inertia.resize(n);
  p.material.resize(n);
  p.mass.resize(n);
  p.id.resize(n);
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const SphereSpec& s = spheres[i];
    const double r = s.radius;
    const double m = w.model.materials[s.material].density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
    p.position[i] = s.position;
    p.velocity[i] = s.velocity;  // at t = 0; the first kick is a half kick
    p.omega[i] = s.omega;
    p.radius[i] = r;
    p.mass[i] = m;
    p.inv_mass[i] = 1.0 / m;
    p.inv_inertia[i] = 1.0 / (0.4 * m * r * r);  // Eq 2-8
    p.material[i] = s.material;
    p.id[i] = i;
  }
  if (!clumps.empty()) {
    ClumpState& k = p.clumps;
    p.clump.assign(n, -1);
    k.member_begin.push_back(0);
    std::size_t i = spheres.size();
    for (std::size_t c = 0; c < clumps.size(); ++c) {
      const ClumpSpec& s = clumps[c];
      k.position.push_back(s.position);
      k.velocity.push_back(s.velocity);
      k.orientation.push_back(s.orientation.normalized());
      k.angular_momentum.push_back(detail::angularMomentum(k.orientation.back(), s.principal_inertia, s.omega));
      k.mass.push_back(s.mass);
      k.inertia.push_back(s.principal_inertia);
      k.id.push_back(n + c);  // ids after the balls': one id space for every body
      for (const geometry::Sphere& m : s.members) {
        p.radius[i] = m.radius;
        p.mass[i] = s.mass;  // a member's dashpots and time-step criterion see the whole body
        p.inv_mass[i] = 1.0 / s.mass;
        p.inv_inertia[i] = 1.0 / s.principal_inertia.minCoeff();
        p.material[i] = s.material;
        p.id[i] = i;
        p.clump[i] = static_cast<std::int32_t>(c);
        k.member_ball.push_back(static_cast<std::uint32_t>(i));
        k.member_offset.push_back(m.centre);
        ++i;
      }
      k.member_begin.push_back(static_cast<std::uint32_t>(k.member_ball.size()));
      w.placeMembers(c);
    }
  }
  w.audit = auditTimestep(w.model, p);
  w.dt = w.audit.chosen;
  w.initialise(threads);
  w.relax_pending = w.model.relaxation.steps > 0;
}

World::World(Model model, WorldState state, int threads) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.model = std::move(model);
  const std::string msg = validateModel(w.model, {});
  if (!msg.empty()) throw std::invalid_argument(msg);
  w.p = std::move(state.particles);
  w.time = state.time;
  w.step = state.step;
  w.half_kick_pending = state.half_kick_pending;
  if (w.p.size() > 0) w.audit = auditTimestep(w.model, w.p);  // nothing to audit in an empty world
  w.audit.chosen = state.dt;  // the run continues with the step it had
  w.dt = state.dt;
  w.initialise(threads);
  // Contact history: build the lists now and take the saved shear forces.
  w.prepareStage();
  w.rebuildNeighbours();
  for (const PairHistory& h : state.pair_history) {
    const auto b = w.pairs.partner.begin() + w.pairs.row_offset[h.i];
    const auto e = w.pairs.partner.begin() + w.pairs.row_offset[h.i + 1];
    const auto it = std::lower_bound(b, e, h.j);
    if (it == e || *it != h.j)
      throw std::invalid_argument("checkpoint: contact history for a pair that is not in contact range");
    w.pair_shear[it - w.pairs.partner.begin()] = h.shear;
    if (h.relax_offset > 0) {
      if (w.pair_relax.empty()) {
        w.pair_relax.assign(w.pairs.size(), 0.0);
        w.wall_relax.assign(w.wall_index.size(), 0.0);
      }
      w.pair_relax[it - w.pairs.partner.begin()] = h.relax_offset;
    }
  }
  for (const WallHistory& h : state.wall_history) {
    if (h.wall >= w.walls.size()) throw std::invalid_argument("checkpoint: wall contact history for a missing wall");
    if (!w.walls[h.wall].active) continue;  // the wall was removed: its contacts went with it
    bool found = false;
    for (std::uint32_t c = w.wall_offset[h.particle]; c < w.wall_offset[h.particle + 1]; ++c)
      if (w.wall_index[c] == h.wall) {
        w.wall_shear[c] = h.shear;
        if (h.relax_offset > 0) {
          if (w.pair_relax.empty()) {
            w.pair_relax.assign(w.pairs.size(), 0.0);
            w.wall_relax.assign(w.wall_index.size(), 0.0);
          }
          w.wall_relax[c] = h.relax_offset;
        }
        found = true;
      }
    if (!found)
      throw std::invalid_argument("checkpoint: wall contact history for a ball out of wall range");
  }
}

World::~World() = default;

void World::Impl::initialise(int requested_threads) {
  threads = requested_threads > 0 ? requested_threads : omp_get_max_threads();
  has_clumps = p.clumps.size() > 0;
  buildPairProps();
  walls.resize(model.walls.size());
  for (std::size_t k = 0; k < walls.size(); ++k) walls[k].setup(model.walls[k]);
  wall_moving.assign(walls.size(), 0);
  bool any_moving = false;
  for (std::size_t k = 0; k < walls.size(); ++k) {
    wall_moving[k] = model.walls[k].motion.isStatic() ? 0 : 1;
    any_moving = any_moving || wall_moving[k];
  }
  if (any_moving) {
    wall_work.assign(p.size(), 0.0);
    wall_work_gross.assign(p.size(), 0.0);
  }
  // Gravity in force at the current time.
  gravity = model.gravity;
  for (const GravityChange& g : model.gravity_changes)
    if (g.time <= time) gravity = g.vector;
  if (model.skin > 0) {
    skin = model.skin;
  } else {
    double sum = 0;
    for (double r : p.radius) sum += r;
    skin = p.size() ? 0.2 * sum / static_cast<double>(p.size()) : 1e-3;
  }
  const std::size_t n = p.size();
  acc_force.assign(n, Vec3::Zero());
  acc_torque.assign(n, Vec3::Zero());
  need_rebuild = true;
}

void World::Impl::buildPairProps() {
  nm = model.materials.size();
  ball_ball.resize(nm * nm);
  ball_wall.resize(nm * nm);
  for (std::size_t a = 0; a < nm; ++a)
    for (std::size_t b = 0; b < nm; ++b) {
      ball_ball[a * nm + b] = detail::ballBallProps(model.materials[a], model.materials[b]);
      ball_wall[a * nm + b] = detail::ballWallProps(model.materials[a], model.materials[b]);
    }
}

// ---------------------------------------------------------------------------
// Stage 1: prepare (gravity schedule, wall poses)

void World::Impl::prepareStage() {
  for (const GravityChange& g : model.gravity_changes) {
    if (g.time <= time && g.time > time - dt && gravity != g.vector) {
      gravity = g.vector;
      energy_ref_valid = false;  // gravity did work on the system: new reference
    }
  }
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const bool was_active = walls[k].active;
    walls[k].update(model.walls[k], time);
    if (walls[k].active && !was_active) need_rebuild = true;
    if (walls[k].active != was_active) energy_ref_valid = false;
    if (walls[k].displacementSinceReference() > 0.5 * skin) need_rebuild = true;
  }
  if (last_max_disp2 > 0.25 * skin * skin) need_rebuild = true;
}

// ---------------------------------------------------------------------------
// Stage 2: neighbours (with contact history carried over)

void World::Impl::rebuildNeighbours() {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = p.size();
  detail::PairList old = std::move(pairs);
  std::vector<Vec3> old_shear = std::move(pair_shear);
  std::vector<double> old_relax = std::move(pair_relax);
  const bool relax = !old_relax.empty();
  finder.build(p.position, p.radius, skin, teamSize(), pairs, model.max_grid_levels, p.clump);
  const std::size_t np = pairs.size();
  pair_shear.assign(np, Vec3::Zero());
  pair_touch.assign(np, 0);
  if (relax) pair_relax.assign(np, 0.0);
  // Carry shear history over by merging old and new rows (both sorted by j).
  if (!old.row_offset.empty()) {
#pragma omp parallel for schedule(static) num_threads(teamSize())
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t a = old.row_offset[i], b = pairs.row_offset[i];
      const std::uint32_t ae = old.row_offset[i + 1], be = pairs.row_offset[i + 1];
      while (a < ae && b < be) {
        if (old.partner[a] < pairs.partner[b]) ++a;
        else if (old.partner[a] > pairs.partner[b]) ++b;
        else {
          if (relax) pair_relax[b] = old_relax[a];
          pair_shear[b++] = old_shear[a++];
        }
      }
    }
  }
  // Wall candidates: balls within r + skin of an active wall.
  std::vector<std::uint32_t> old_offset = std::move(wall_offset), old_index = std::move(wall_index);
  std::vector<Vec3> old_wshear = std::move(wall_shear);
  std::vector<double> old_wrelax = std::move(wall_relax);
  wall_offset.assign(n + 1, 0);
  wall_index.clear();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < walls.size(); ++k) {
      if (!walls[k].active) continue;
      if (walls[k].distance(model.walls[k], p.position[i]) < p.radius[i] + skin)
        wall_index.push_back(static_cast<std::uint32_t>(k));
    }
    wall_offset[i + 1] = static_cast<std::uint32_t>(wall_index.size());
  }
  wall_shear.assign(wall_index.size(), Vec3::Zero());
  wall_touch.assign(wall_index.size(), 0);
  if (relax) wall_relax.assign(wall_index.size(), 0.0);
  if (!old_offset.empty()) {
    for (std::size_t i = 0; i < n; ++i)
      for (std::uint32_t c = wall_offset[i]; c < wall_offset[i + 1]; ++c)
        for (std::uint32_t o = old_offset[i]; o < old_offset[i + 1]; ++o)
          if (old_index[o] == wall_index[c]) {
            wall_shear[c] = old_wshear[o];
            if (relax) wall_relax[c] = old_wrelax[o];
          }
  }
  ref_position = p.position;
  for (auto& wr : walls) wr.setReference();
  last_max_disp2 = 0.0;
  need_rebuild = false;
  assignRanges();
  ++stats.neighbour_rebuilds;
  stats.pairs_in_list = np;
  stats.wall_candidates = wall_index.size();
  stats.neighbour_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void World::Impl::assignRanges() {
  const std::size_t n = p.size();
  const int team = teamSize();
  range_begin.resize(static_cast<std::size_t>(team) + 1);
  for (int t = 0; t <= team; ++t) range_begin[t] = static_cast<std::uint32_t>(n * static_cast<std::size_t>(t) / team);
  cross_index.assign(pairs.size(), kNotCross);
  std::uint32_t slots = 0;
  for (int t = 0; t < team; ++t)
    for (std::uint32_t i = range_begin[t]; i < range_begin[t + 1]; ++i)
      for (std::uint32_t k = pairs.row_offset[i]; k < pairs.row_offset[i + 1]; ++k)
        if (pairs.partner[k] >= range_begin[t + 1]) cross_index[k] = slots++;
  cross.resize(slots);
}

// ---------------------------------------------------------------------------
// Stages 3, 4 and 6: contacts, gather and integrate in one pass
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

template <class Law>
[[gnu::always_inline]] inline bool World::Impl::evaluatePair(std::size_t i, std::uint32_t k, Vec3& fi, Vec3& ti, Vec3& fj,
                                      Vec3& tj, StepChecks& c) {
  const std::uint32_t j = pairs.partner[k];
  const Vec3 xi = p.position[i];
  const Vec3 d = p.position[j] - xi;
  const double ri = p.radius[i], rj = p.radius[j];
  const double rsum = ri + rj;
  const double dist2 = d.squaredNorm();
  if (dist2 >= rsum * rsum) {
    pair_touch[k] = 0;
    pair_shear[k].setZero();
    if (relaxing()) pair_relax[k] = 0.0;  // separated: a new touch gets the full force
    return false;
  }
  const double dist = std::sqrt(dist2);
  detail::ContactGeometry g;
  g.normal = dist > 0 ? Vec3(d * (1.0 / dist)) : Vec3(Vec3::UnitZ());
  g.overlap = rsum - dist;
  const Vec3 cp = xi + g.normal * (ri - 0.5 * g.overlap);  // contact point: middle of the overlap
  if (relaxing()) {
    // Initial overlap being relaxed: the law sees only the overlap beyond the offset.
    g.overlap -= relax_factor * pair_relax[k];
    if (g.overlap <= 0) {
      pair_touch[k] = 0;
      pair_shear[k].setZero();
      return false;
    }
  }
  const Vec3 ai = cp - xi, aj = cp - p.position[j];
  g.rel_velocity = (p.velocity[j] + p.omega[j].cross(aj)) - (p.velocity[i] + p.omega[i].cross(ai));
  g.r_tilde = 2.0 * ri * rj / rsum;  // Eq 2-24
  const double mi = p.mass[i], mj = p.mass[j];
  g.damping_mass = detail::dampingMass(model.contact.damping_mass, mi, mj);
  const PairProps& props = ball_ball[static_cast<std::size_t>(p.material[i]) * nm + static_cast<std::size_t>(p.material[j])];
  const detail::ContactResult res = detail::evaluateContact<Law>(props, model.contact, g, dt, pair_shear[k]);
  fi = res.force;
  ti = ai.cross(res.force);
  fj = -res.force;
  tj = aj.cross(fj);
  pair_touch[k] = 1;
  const double r_small = std::min(ri, rj);
  if (g.overlap > model.watchdog.max_overlap_fraction * r_small)
    mergeWorst(c, g.overlap / r_small, (std::uint64_t(i) << 32) | j);
  return true;
}

template <class Law>
inline void World::Impl::addWallForces(std::size_t i, Vec3& f, Vec3& t, StepChecks& c) {
  const Vec3 xi = p.position[i];
  const double ri = p.radius[i];
  for (std::uint32_t w = wall_offset[i]; w < wall_offset[i + 1]; ++w) {
    const std::uint32_t wk = wall_index[w];
    const detail::WallRuntime& wr = walls[wk];
    detail::WallContact wc;
    if (!wr.active || !wr.contact(model.walls[wk], xi, ri, wc)) {
      wall_touch[w] = 0;
      wall_shear[w].setZero();
      if (relaxing()) wall_relax[w] = 0.0;
      continue;
    }
    detail::ContactGeometry g;
    g.normal = wc.normal;
    g.overlap = wc.overlap;
    const Vec3 cp = xi + g.normal * (ri - 0.5 * g.overlap);
    if (relaxing()) {
      g.overlap -= relax_factor * wall_relax[w];
      if (g.overlap <= 0) {
        wall_touch[w] = 0;
        wall_shear[w].setZero();
        continue;
      }
    }
    const Vec3 ai = cp - xi;
    const Vec3 v_wall = wr.velocityAt(cp);
    g.rel_velocity = v_wall - (p.velocity[i] + p.omega[i].cross(ai));
    g.r_tilde = ri;            // mirror-image ball (ref §4.2)
    g.damping_mass = p.mass[i];  // ball–wall dashpot uses the ball's mass (Eq 2-18)
    const PairProps& props =
        ball_wall[static_cast<std::size_t>(p.material[i]) * nm + static_cast<std::size_t>(model.walls[wk].material)];
    const detail::ContactResult res = detail::evaluateContact<Law>(props, model.contact, g, dt, wall_shear[w]);
    f += res.force;
    t += ai.cross(res.force);
    wall_touch[w] = 1;
    if (!wall_work.empty() && wall_moving[wk]) {
      // Power of the wall on the ball, F . v_wall (the energy watchdog's work input).
      const double dw = dt * res.force.dot(v_wall);
      wall_work[i] += dw;
      wall_work_gross[i] += std::abs(dw);
    }
    if (g.overlap > model.watchdog.max_overlap_fraction * ri)
      mergeWorst(c, g.overlap / ri, (std::uint64_t(i) << 32) | kWallBit | wk);
  }
}

template <class Law>
void World::Impl::forcePass(bool integrate_now, double h, StepChecks& merged) {
  const int team = static_cast<int>(range_begin.size()) - 1;
  // Clump members are integrated with their clump after the pass. A local copy:
  // the stores into the accumulators could alias the member flag otherwise.
  const std::int32_t* const clump_of = has_clumps ? p.clump.data() : nullptr;
#pragma omp parallel num_threads(team)
  {
    const int th = omp_get_thread_num();
    const std::uint32_t b = range_begin[th], e = range_begin[th + 1];
    StepChecks local;
    // Phase A: pairs whose second ball belongs to a later range.
    for (std::uint32_t i = b; i < e; ++i)
      for (std::uint32_t k = pairs.row_offset[i]; k < pairs.row_offset[i + 1]; ++k) {
        if (pairs.partner[k] < e) continue;
        CrossSlot& s = cross[cross_index[k]];
        evaluatePair<Law>(i, k, s.fi, s.ti, s.fj, s.tj, local);
      }
#pragma omp barrier
    // Phase B: start every ball of the range with the cross contributions it
    // receives (pairs (i', p), i' < b, ascending i').
    for (std::uint32_t q = b; q < e; ++q) {
      Vec3 f = Vec3::Zero(), t = Vec3::Zero();
      for (std::uint32_t c = pairs.col_offset[q]; b > 0 && c < pairs.col_offset[q + 1]; ++c) {
        const std::uint32_t k = pairs.col_pair[c];
        if (cross_index[k] == kNotCross) break;  // the rest come from this range
        if (!pair_touch[k]) continue;
        f += cross[cross_index[k]].fj;
        t += cross[cross_index[k]].tj;
      }
      acc_force[q] = f;
      acc_torque[q] = t;
    }
    // ...then every ball's own row (scattering to partners in the range) and walls.
    for (std::uint32_t i = b; i < e; ++i) {
      Vec3 f = acc_force[i], t = acc_torque[i];
      for (std::uint32_t k = pairs.row_offset[i]; k < pairs.row_offset[i + 1]; ++k) {
        if (cross_index[k] != kNotCross) {
          if (!pair_touch[k]) continue;
          f += cross[cross_index[k]].fi;
          t += cross[cross_index[k]].ti;
          continue;
        }
        Vec3 fi, ti, fj, tj;
        if (!evaluatePair<Law>(i, k, fi, ti, fj, tj, local)) continue;
        f += fi;
        t += ti;
        const std::uint32_t j = pairs.partner[k];
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

inline void World::Impl::integrate(std::size_t i, const Vec3& f_contact, const Vec3& torque,
                                   double h, StepChecks& c) {
  const double inv_m = p.inv_mass[i];
  Vec3 f = f_contact + gravity / inv_m;  // generalised force incl. gravity (Eq 2-14)
  Vec3 t = torque;
  const double alpha = model.contact.local_damping;
  if (alpha > 0) {
    // Cundall's local damping, Eq 2-15 in its sign form: -alpha |F| sign(v) per component.
    for (int a = 0; a < 3; ++a) {
      f[a] -= alpha * std::abs(f[a]) * ((p.velocity[i][a] > 0) - (p.velocity[i][a] < 0));
      t[a] -= alpha * std::abs(t[a]) * ((p.omega[i][a] > 0) - (p.omega[i][a] < 0));
    }
  }
  p.velocity[i] += (h * inv_m) * f;               // Eq 2-11
  p.omega[i] += (h * p.inv_inertia[i]) * t;       // Eq 2-12 (sphere: no gyroscopic term)
  p.position[i] += dt * p.velocity[i];            // Eq 2-13
  if (!p.position[i].allFinite() || !p.velocity[i].allFinite()) c.non_finite = true;
  c.max_disp2 = std::max(c.max_disp2, (p.position[i] - ref_position[i]).squaredNorm());
}

/// Sets the members' positions, velocities and spins from their clump's state.
void World::Impl::placeMembers(std::size_t c) {
  ClumpState& k = p.clumps;
  const Quat q = k.orientation[c];
  const Vec3 w = detail::angularVelocity(q, k.inertia[c], k.angular_momentum[c]);
  for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
    const std::uint32_t i = k.member_ball[m];
    const Vec3 arm = q * k.member_offset[m];
    p.position[i] = k.position[c] + arm;
    p.velocity[i] = k.velocity[c] + w.cross(arm);
    p.omega[i] = w;
  }
}

/// Resultant contact force and moment about the centre of mass (Eq 2-44, 2-46),
/// summed over the members in their fixed order.
void World::Impl::clumpLoad(std::size_t c, Vec3& force, Vec3& torque) const {
  const ClumpState& k = p.clumps;
  force.setZero();
  torque.setZero();
  for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
    const std::uint32_t i = k.member_ball[m];
    force += acc_force[i];
    torque += acc_torque[i] + (p.position[i] - k.position[c]).cross(acc_force[i]);
  }
}

void World::Impl::integrateClumps(double h, StepChecks& merged) {
  ClumpState& k = p.clumps;
  const double alpha = model.contact.local_damping;
#pragma omp parallel num_threads(teamSize())
  {
    StepChecks local;
#pragma omp for schedule(static)
    for (std::size_t c = 0; c < k.size(); ++c) {
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
      k.velocity[c] += (h / k.mass[c]) * f;     // Eq 2-11 for the body
      k.angular_momentum[c] += h * t;           // Eq 2-45
      k.position[c] += dt * k.velocity[c];      // Eq 2-13
      detail::rotateFree(k.orientation[c], k.inertia[c], k.angular_momentum[c], dt);
      placeMembers(c);
      if (!k.position[c].allFinite() || !k.velocity[c].allFinite() || !k.angular_momentum[c].allFinite())
        local.non_finite = true;
      for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
        const std::uint32_t i = k.member_ball[m];
        local.max_disp2 = std::max(local.max_disp2, (p.position[i] - ref_position[i]).squaredNorm());
      }
    }
#pragma omp critical
    mergeChecks(merged, local);
  }
}

// ---------------------------------------------------------------------------
// Energy (observed steps only)

template <class Law>
Energy World::Impl::energy(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const {
  Energy e;
  const ClumpState& cl = p.clumps;
  for (std::size_t c = 0; c < cl.size(); ++c) {
    e.kinetic_translational += 0.5 * cl.mass[c] * obs_clump_velocity[c].squaredNorm();
    const Vec3 body_w = cl.orientation[c].conjugate() * obs_clump_omega[c];
    e.kinetic_rotational += 0.5 * body_w.dot(body_w.cwiseProduct(cl.inertia[c]));
    e.potential_gravity -= cl.mass[c] * gravity.dot(cl.position[c]);
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!isMember(i)) {
      e.kinetic_translational += 0.5 * p.mass[i] * v[i].squaredNorm();
      e.kinetic_rotational += 0.5 / p.inv_inertia[i] * w[i].squaredNorm();
      e.potential_gravity -= p.mass[i] * gravity.dot(p.position[i]);
    }
    for (std::uint32_t k = pairs.row_offset[i]; k < pairs.row_offset[i + 1]; ++k) {
      if (!pair_touch[k]) continue;
      const std::uint32_t j = pairs.partner[k];
      const double rsum = p.radius[i] + p.radius[j];
      double overlap = rsum - (p.position[j] - p.position[i]).norm();
      if (relaxing()) overlap -= relax_factor * pair_relax[k];
      const PairProps& props = ball_ball[static_cast<std::size_t>(p.material[i]) * nm +
                                         static_cast<std::size_t>(p.material[j])];
      e.elastic += detail::elasticEnergy<Law>(props, overlap, 2.0 * p.radius[i] * p.radius[j] / rsum,
                                              pair_shear[k]);
    }
    for (std::uint32_t c = wall_offset[i]; c < wall_offset[i + 1]; ++c) {
      if (!wall_touch[c]) continue;
      const std::uint32_t wk = wall_index[c];
      detail::WallContact wc;
      if (!walls[wk].contact(model.walls[wk], p.position[i], p.radius[i], wc)) continue;
      const PairProps& props = ball_wall[static_cast<std::size_t>(p.material[i]) * nm +
                                         static_cast<std::size_t>(model.walls[wk].material)];
      const double overlap = wc.overlap - (relaxing() ? relax_factor * wall_relax[c] : 0.0);
      e.elastic += detail::elasticEnergy<Law>(props, overlap, p.radius[i], wall_shear[c]);
    }
  }
  return e;
}

Energy World::Impl::energyAny(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const {
  return model.contact.law == ContactLaw::Linear ? energy<detail::LinearLaw>(v, w)
                                                 : energy<detail::HertzMindlinLaw>(v, w);
}

// ---------------------------------------------------------------------------
// Stage 7: watchdog

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
       "v sqrt(m/k): stiffen them), or "
    << stepAdvice();
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

bool World::Impl::energyCheckApplies() const {
  // Moving walls do work: it is counted (wall_work) and allowed for in checkEnergy.
  // Relaxing initial overlaps does work on the system (the offsets shrink).
  if (relaxing()) return false;
  return model.watchdog.max_energy_growth > 0 && p.size() > 0;
}

/// Takes every touching contact's overlap as its relaxation offset (first step
/// of a world built with Model::relaxation.steps > 0).
void World::Impl::startRelaxation() {
  relax_pending = false;
  pair_relax.assign(pairs.size(), 0.0);
  wall_relax.assign(wall_index.size(), 0.0);
  bool any = false;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::uint32_t k = pairs.row_offset[i]; k < pairs.row_offset[i + 1]; ++k) {
      const std::uint32_t j = pairs.partner[k];
      const double overlap = p.radius[i] + p.radius[j] - (p.position[j] - p.position[i]).norm();
      if (overlap > 0) {
        pair_relax[k] = overlap;
        any = true;
      }
    }
    for (std::uint32_t c = wall_offset[i]; c < wall_offset[i + 1]; ++c) {
      const std::uint32_t wk = wall_index[c];
      detail::WallContact wc;
      if (walls[wk].active && walls[wk].contact(model.walls[wk], p.position[i], p.radius[i], wc) &&
          wc.overlap > 0) {
        wall_relax[c] = wc.overlap;
        any = true;
      }
    }
  }
  if (!any) {
    pair_relax.clear();
    wall_relax.clear();
  }
}

/// Offset factor of this step; frees the offsets once the relaxation is over.
void World::Impl::updateRelaxation() {
  const auto n = static_cast<std::uint64_t>(std::max(0, model.relaxation.steps));
  if (step >= n) {
    pair_relax.clear();
    pair_relax.shrink_to_fit();
    wall_relax.clear();
    wall_relax.shrink_to_fit();
    energy_ref_valid = false;  // the energy check starts afresh from the relaxed state
    return;
  }
  // Smoothstep: the offset starts and ends shrinking at zero rate, so the bodies
  // are not jerked into motion at the start nor left moving at the end (a linear
  // ramp leaves them with up to twice its rate). Peak rate 1.5 x offset / (n dt).
  const double x = static_cast<double>(step) / static_cast<double>(n);
  relax_factor = 1.0 - x * x * (3.0 - 2.0 * x);
}

void World::Impl::checkEnergy(const Energy& e) {
  if (!energyCheckApplies()) return;
  if (!energy_ref_valid) {
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
    energy_ref = e.total();
    energy_scale = std::abs(e.kinetic_translational + e.kinetic_rotational + e.elastic) +
                   mass * gravity.norm() * extent;
    energy_ref_valid = energy_scale > 0;
    std::fill(wall_work.begin(), wall_work.end(), 0.0);
    std::fill(wall_work_gross.begin(), wall_work_gross.end(), 0.0);
    return;
  }
  // Work of the moving walls since the reference, summed in ball order. The
  // allowance grows with the gross work so that the O(dt^2) error of counting it
  // cannot add up to a false alarm in a long run with a working wall (a crusher).
  double work = 0.0, gross = 0.0;
  for (std::size_t i = 0; i < wall_work.size(); ++i) {
    work += wall_work[i];
    gross += wall_work_gross[i];
  }
  const double growth = e.total() - energy_ref - work;
  if (growth <= model.watchdog.max_energy_growth * (energy_scale + gross)) return;
  std::size_t fastest = 0;
  for (std::size_t i = 1; i < p.size(); ++i)
    if (p.velocity[i].squaredNorm() > p.velocity[fastest].squaredNorm()) fastest = i;
  std::ostringstream s;
  s << "watchdog: mechanical energy grew by " << fmtNum(growth) << " J (" << fmtNum(growth / energy_scale)
    << " of its scale " << fmtNum(energy_scale) << " J, limit watchdog.max_energy_growth = "
    << model.watchdog.max_energy_growth << ") at t = " << fmtNum(time) << " s (step " << step << ") "
    << (wall_work.empty() ? std::string("with no work input")
                          : "beyond the " + fmtNum(work) + " J of work done by the moving walls")
    << "; fastest particle " << p.id[fastest] << " at "
    << fmtNum(p.velocity[fastest].norm()) << " m/s. " << stepAdvice();
  throw WatchdogError(s.str());
}

// The touching contacts as springs between rigid bodies (free balls and clumps),
// for the step check. A shear spring counts only while it sticks.
template <class Law>
void World::Impl::buildContactNetwork(detail::ContactNetwork& net) const {
  net.bodies.clear();  // capacity kept between checks
  net.body_names.clear();
  net.contacts.clear();
  const std::size_t n = p.size();
  const ClumpState& k = p.clumps;
  std::vector<std::int32_t> body_of(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (isMember(i)) continue;
    body_of[i] = static_cast<std::int32_t>(net.bodies.size());
    const double inertia = 1.0 / p.inv_inertia[i];
    net.bodies.push_back({p.inv_mass[i], inertia * geometry::Mat3::Identity(),
                          p.inv_inertia[i] * geometry::Mat3::Identity()});
    net.body_names.push_back("particle " + std::to_string(p.id[i]));
  }
  const auto first_clump = static_cast<std::int32_t>(net.bodies.size());
  for (std::size_t c = 0; c < k.size(); ++c) {
    const geometry::Mat3 r = k.orientation[c].toRotationMatrix();
    net.bodies.push_back({1.0 / k.mass[c], r * k.inertia[c].asDiagonal() * r.transpose(),
                          r * k.inertia[c].cwiseInverse().asDiagonal() * r.transpose()});
    net.body_names.push_back("clump " + std::to_string(k.id[c]));
  }
  if (has_clumps)
    for (std::size_t i = 0; i < n; ++i)
      if (isMember(i)) body_of[i] = first_clump + p.clump[i];
  auto centre = [&](std::size_t i) { return isMember(i) ? k.position[p.clump[i]] : p.position[i]; };
  const ContactModel& cm = model.contact;
  auto add = [&](std::size_t i, std::int32_t b, const Vec3& normal, const Vec3& cp, const Vec3& centre_b,
                 double overlap, double r_tilde, double damping_mass, const PairProps& props, const Vec3& shear) {
    double secant, tangent;
    Law::normal(props, overlap, r_tilde, secant, tangent);
    const double fn = secant * overlap;
    const double limit = props.friction * fn;
    const bool sticks = shear.squaredNorm() < limit * limit * (1.0 - 1e-9);
    detail::NetworkContact c;
    c.a = body_of[i];
    c.b = b;
    c.normal = normal;
    c.lever_a = cp - centre(i);
    c.lever_b = cp - centre_b;
    c.kn = tangent;
    c.ks = sticks ? Law::shear(props, fn, r_tilde) : 0.0;
    // The dashpots of evaluateContact (Eq 2-16..2-18); the shear one only while sticking.
    c.cn = detail::dashpot(cm.damping_normal, damping_mass, c.kn);
    c.cs = detail::dashpot(cm.damping_shear, damping_mass, c.ks);
    net.contacts.push_back(c);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double ri = p.radius[i];
    for (std::uint32_t q = pairs.row_offset[i]; q < pairs.row_offset[i + 1]; ++q) {
      if (!pair_touch[q]) continue;
      const std::uint32_t j = pairs.partner[q];
      if (body_of[i] == body_of[j]) continue;  // members of one clump
      const Vec3 d = p.position[j] - p.position[i];
      const double dist = d.norm(), rj = p.radius[j];
      const Vec3 normal = dist > 0 ? Vec3(d / dist) : Vec3(Vec3::UnitZ());
      double overlap = ri + rj - dist;
      const Vec3 cp = p.position[i] + normal * (ri - 0.5 * overlap);
      if (relaxing()) overlap -= relax_factor * pair_relax[q];
      if (overlap <= 0) continue;
      const PairProps& props = ball_ball[static_cast<std::size_t>(p.material[i]) * nm + static_cast<std::size_t>(p.material[j])];
      const double md = detail::dampingMass(cm.damping_mass, p.mass[i], p.mass[j]);
      add(i, body_of[j], normal, cp, centre(j), overlap, 2.0 * ri * rj / (ri + rj), md, props, pair_shear[q]);
    }
    for (std::uint32_t w = wall_offset[i]; w < wall_offset[i + 1]; ++w) {
      if (!wall_touch[w]) continue;
      const std::uint32_t wk = wall_index[w];
      detail::WallContact wc;
      if (!walls[wk].active || !walls[wk].contact(model.walls[wk], p.position[i], ri, wc)) continue;
      const Vec3 cp = p.position[i] + wc.normal * (ri - 0.5 * wc.overlap);
      const double overlap = wc.overlap - (relaxing() ? relax_factor * wall_relax[w] : 0.0);
      if (overlap <= 0) continue;
      const PairProps& props =
          ball_wall[static_cast<std::size_t>(p.material[i]) * nm + static_cast<std::size_t>(model.walls[wk].material)];
      add(i, -1, wc.normal, cp, cp, overlap, ri, p.mass[i], props, wall_shear[w]);
    }
  }
}

void World::Impl::checkNetworkStep() {
  if (model.watchdog.network_iterations <= 0) return;
  detail::ContactNetwork& net = network;
  if (model.contact.law == ContactLaw::Linear)
    buildContactNetwork<detail::LinearLaw>(net);
  else
    buildContactNetwork<detail::HertzMindlinLaw>(net);
  detail::iterateSpectrum(net, 2.0 / dt, model.watchdog.network_iterations, spectrum);
  // Stable while L < 4 / dt^2 (contact_spectrum.h): the ratio dt / (2 / sqrt(L)).
  const double ratio = 0.5 * dt * std::sqrt(spectrum.eigenvalue);
  ++stats.network_checks;
  stats.network_step_ratio = std::max(stats.network_step_ratio, ratio);
  if (ratio <= 1.0) return;
  const double omega = std::sqrt(spectrum.stiffness);
  const double stable = detail::stableStep(spectrum.stiffness, spectrum.damping);
  std::ostringstream s;
  s << "watchdog: at t = " << fmtNum(time) << " s (step " << step << ") the step is unstable for the contact "
    << "network: its fastest mode (" << net.contacts.size() << " touching contacts; largest share on "
    << (spectrum.body >= 0 ? net.body_names[static_cast<std::size_t>(spectrum.body)] : std::string("none"))
    << ") has omega = " << fmtNum(omega) << " rad/s and dashpots " << fmtNum(spectrum.damping)
    << " 1/s, stable only for dt < " << fmtNum(stable) << " s (" << fmtNum(stable / audit.critical)
    << " x critical). Sticking contacts would creep and slip without a blow-up, unseen by the energy check. "
       "The critical step counts one contact per body; a body pressed by several, a stuck shear spring that "
       "also turns it, and their dashpots make it vibrate faster (ref §7a). "
    << stepAdvice();
  throw WatchdogError(s.str());
}

// ---------------------------------------------------------------------------
// One step

void World::Impl::doStep(const std::function<void(const Snapshot&)>& observer) {
  const std::size_t n = p.size();
  prepareStage();                                     // 1
  if (need_rebuild) rebuildNeighbours();              // 2
  if (relax_pending) startRelaxation();
  if (relaxing()) updateRelaxation();
  const double h = half_kick_pending ? 0.5 * dt : dt;
  const int interval = std::max(1, model.watchdog.check_interval);
  const bool energy_due = (step % static_cast<std::uint64_t>(interval)) == 0 && energyCheckApplies();
  int network_every = std::max(1, model.watchdog.network_interval);
  if (dt > audit.automatic * (1.0 + 1e-12)) network_every = std::min(network_every, interval);  // a forced step
  const bool network_due =
      model.watchdog.network_iterations > 0 && step % static_cast<std::uint64_t>(network_every) == 0;
  const bool observe = observer || energy_due || network_due;
  StepChecks merged;
  // 3 + 4 (+ 6 unless observed): contacts, gather, integrate.
  if (model.contact.law == ContactLaw::Linear)
    forcePass<detail::LinearLaw>(!observe, h, merged);
  else
    forcePass<detail::HertzMindlinLaw>(!observe, h, merged);
  if (has_clumps && !observe) integrateClumps(h, merged);
  checkOverlap(merged);

  if (observe) {
    // 5: the snapshot needs the whole-step state before the kick.
    obs_velocity.resize(n);
    obs_omega.resize(n);
    // v(t) = v(t - dt/2) + a(t) dt/2; at the first step v holds v(0) already.
    const double half = half_kick_pending ? 0.0 : 0.5 * dt;
    for (std::size_t i = 0; i < n; ++i) {
      obs_velocity[i] = p.velocity[i] + half * (acc_force[i] * p.inv_mass[i] + gravity);
      obs_omega[i] = p.omega[i] + half * p.inv_inertia[i] * acc_torque[i];
    }
    const ClumpState& k = p.clumps;
    obs_clump_velocity.resize(k.size());
    obs_clump_omega.resize(k.size());
    std::vector<Vec3> clump_force(k.size());
    for (std::size_t c = 0; c < k.size(); ++c) {
      Vec3 torque;
      clumpLoad(c, clump_force[c], torque);
      clump_force[c] += gravity * k.mass[c];
      obs_clump_velocity[c] = k.velocity[c] + (half / k.mass[c]) * clump_force[c];
      obs_clump_omega[c] =
          detail::angularVelocity(k.orientation[c], k.inertia[c], k.angular_momentum[c] + half * torque);
      for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
        const std::uint32_t i = k.member_ball[m];
        obs_velocity[i] = obs_clump_velocity[c] + obs_clump_omega[c].cross(p.position[i] - k.position[c]);
        obs_omega[i] = obs_clump_omega[c];
      }
    }
    Snapshot s;
    s.time = time;
    s.step = step;
    s.energy = energyAny(obs_velocity, obs_omega);
    // Checked whenever it is computed, not only every check_interval steps: an
    // observer may end the run (a drop test ends at the rebound) before the next
    // scheduled check would see a blow-up.
    if (energyCheckApplies()) checkEnergy(s.energy);
    if (network_due) checkNetworkStep();
    if (observer) {
      std::vector<Vec3> total(n);  // total force including gravity
      for (std::size_t i = 0; i < n; ++i) total[i] = acc_force[i] + gravity * (isMember(i) ? 0.0 : p.mass[i]);
      s.position = p.position;
      s.velocity = obs_velocity;
      s.omega = obs_omega;
      s.force = total;
      s.radius = p.radius;
      s.id = p.id;
      s.material = p.material;
      std::vector<std::uint8_t> active(walls.size());
      for (std::size_t w = 0; w < walls.size(); ++w) active[w] = walls[w].active ? 1 : 0;
      s.wall_active = active;
      s.clump = p.clump;
      s.clump_position = k.position;
      s.clump_velocity = obs_clump_velocity;
      s.clump_omega = obs_clump_omega;
      s.clump_orientation = k.orientation;
      s.clump_force = clump_force;
      s.clump_id = k.id;
      for (std::uint8_t t : pair_touch) s.contacts += t;
      for (std::uint8_t t : wall_touch) s.wall_contacts += t;
      observer(s);
    }
    // 6
#pragma omp parallel num_threads(teamSize())
    {
      StepChecks local;
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < n; ++i)
        if (!isMember(i)) integrate(i, acc_force[i], acc_torque[i], h, local);
#pragma omp critical
      mergeChecks(merged, local);
    }
    if (has_clumps) integrateClumps(h, merged);
  }
  half_kick_pending = false;
  time = static_cast<double>(step + 1) * dt;  // no accumulated round-off in t
  ++step;
  last_max_disp2 = merged.max_disp2;
  if (merged.non_finite) checkFinite();  // 7
}

void World::step(const std::function<void(const Snapshot&)>& observer) { impl_->doStep(observer); }

double World::time() const { return impl_->time; }
std::uint64_t World::stepCount() const { return impl_->step; }
double World::dt() const { return impl_->dt; }
const Model& World::model() const { return impl_->model; }
const ParticleState& World::particles() const { return impl_->p; }
const TimestepAudit& World::timestepAudit() const { return impl_->audit; }
const WorldStats& World::stats() const { return impl_->stats; }
int World::threads() const { return impl_->teamSize(); }
Vec3 World::gravity() const { return impl_->gravity; }

WorldState World::exportState() const {
  const Impl& w = *impl_;
  WorldState s;
  s.time = w.time;
  s.step = w.step;
  s.dt = w.dt;
  s.half_kick_pending = w.half_kick_pending;
  s.particles = w.p;
  for (std::size_t i = 0; i + 1 < w.pairs.row_offset.size(); ++i)
    for (std::uint32_t k = w.pairs.row_offset[i]; k < w.pairs.row_offset[i + 1]; ++k)
      if (!w.pair_shear[k].isZero(0) || (w.relaxing() && w.pair_relax[k] > 0))
        s.pair_history.push_back({static_cast<std::uint32_t>(i), w.pairs.partner[k], w.pair_shear[k],
                                  w.relaxing() ? w.pair_relax[k] : 0.0});
  for (std::size_t i = 0; i + 1 < w.wall_offset.size(); ++i)
    for (std::uint32_t c = w.wall_offset[i]; c < w.wall_offset[i + 1]; ++c)
      if (!w.wall_shear[c].isZero(0) || (w.relaxing() && w.wall_relax[c] > 0))
        s.wall_history.push_back({static_cast<std::uint32_t>(i), w.wall_index[c], w.wall_shear[c],
                                  w.relaxing() ? w.wall_relax[c] : 0.0});
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
