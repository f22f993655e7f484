#pragma once
// World::Impl: the engine's state, grouped by the stage that owns it, and the
// stage functions (one file each in src/stages/). Internal to rocklab_sim.
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "contact_kernel.h"
#include "contact_spectrum.h"
#include "neighbor_list.h"
#include "team_tuner.h"
#include "rocklab/sim/world.h"
#include "wall_runtime.h"

namespace rocklab::sim {

namespace bond_law {
struct BondConstants;
}

// Reduction of the per-step checks; merged in a thread-independent way (max, or).
struct StepChecks {
  double max_disp2 = 0.0;        // m^2, largest squared displacement since the last rebuild
  bool non_finite = false;
  double worst_overlap = 0.0;    // overlap / smaller radius
  std::uint64_t worst_key = 0;   // (i << 32 | j) of that contact; j = kWallBit | wall for walls
};
inline constexpr std::uint64_t kWallBit = 1ull << 31;

inline void mergeWorst(StepChecks& into, double ratio, std::uint64_t key) {
  if (ratio > into.worst_overlap || (ratio == into.worst_overlap && ratio > 0 && key < into.worst_key)) {
    into.worst_overlap = ratio;
    into.worst_key = key;
  }
}

/// Folds one thread's checks into the step's (call inside `omp critical`).
inline void mergeChecks(StepChecks& into, const StepChecks& from) {
  mergeWorst(into, from.worst_overlap, from.worst_key);
  into.max_disp2 = std::max(into.max_disp2, from.max_disp2);
  into.non_finite = into.non_finite || from.non_finite;
}

/// Four significant digits, for messages.
std::string fmtNum(double x);

/// Adds the wall time of its scope to one stage's counter.
class StageTimer {
 public:
  explicit StageTimer(double& seconds) : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
  ~StageTimer() { seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  double& seconds_;
  std::chrono::steady_clock::time_point start_;
};

/// Where a ball touches its partner (a ball or a wall): the one definition for
/// the contact pass, the energy, the network check and the relaxation.
struct ContactPoint {
  Vec3 normal = Vec3::UnitZ();  // unit, from the ball towards its partner
  double overlap = 0.0;         // m, geometric, before any relaxation offset
  Vec3 point = Vec3::Zero();    // m, the middle of the overlap (the torque arms' end)
};

/// The contact of ball i at xi (radius ri) with ball j at xi + d, |d|^2 = dist2,
/// once the test below found them touching: unit normal from i towards j, overlap
/// (m) and the middle of the overlap. Separate outputs, not a ContactPoint: the
/// force pass keeps them in registers (through a struct copied into the contact
/// law's input, the compiler kept the normal in memory).
[[gnu::always_inline]] inline void touchingBallGeometry(const Vec3& xi, const Vec3& d, double dist2, double ri,
                                                        double rj, Vec3& normal, double& overlap, Vec3& point) {
  const double dist = std::sqrt(dist2);
  normal = dist > 0 ? Vec3(d * (1.0 / dist)) : Vec3(Vec3::UnitZ());
  overlap = (ri + rj) - dist;
  point = xi + normal * (ri - 0.5 * overlap);
}

/// The overlap the contact law sees while an initial overlap `offset` relaxes
/// (Model::relaxation): the part beyond `factor` times the offset.
inline double relaxedOverlap(double overlap, double factor, double offset) { return overlap - factor * offset; }

/// Whether balls i and j are apart, from d = xj - xi and their radii.
[[gnu::always_inline]] inline bool ballsApart(double dist2, double ri, double rj) {
  const double rsum = ri + rj;
  return dist2 >= rsum * rsum;
}

/// Ball i at xi (radius ri) against ball j; false when they are apart.
[[gnu::always_inline]] inline bool ballBallTouch(const Vec3& xi, const Vec3& xj, double ri, double rj,
                                                 ContactPoint& g) {
  const Vec3 d = xj - xi;
  const double dist2 = d.squaredNorm();
  if (ballsApart(dist2, ri, rj)) return false;
  touchingBallGeometry(xi, d, dist2, ri, rj, g.normal, g.overlap, g.point);
  return true;
}

/// The same geometry whether they touch or not (overlap < 0: the gap), for
/// contact bonds (§8.1), which hold a pair apart too. Bit for bit what
/// ballBallTouch gives when they touch.
[[gnu::always_inline]] inline void ballBallGeometry(const Vec3& xi, const Vec3& xj, double ri, double rj,
                                                    ContactPoint& g) {
  const Vec3 d = xj - xi;
  const double dist = std::sqrt(d.squaredNorm());
  g.normal = dist > 0 ? Vec3(d * (1.0 / dist)) : Vec3(Vec3::UnitZ());
  g.overlap = (ri + rj) - dist;
  g.point = xi + g.normal * (ri - 0.5 * g.overlap);
}

/// A ball against an active plane or polygon wall; false when apart or the wall
/// is not there (a mesh wall's contacts: World::Impl::wallTouches).
[[gnu::always_inline]] inline bool ballWallTouch(const detail::WallRuntime& runtime, const Wall& wall,
                                                 const Vec3& xi, double ri, ContactPoint& g) {
  detail::WallContact wc;
  if (!runtime.active || !runtime.contact(wall, xi, ri, wc)) return false;
  g.normal = wc.normal;
  g.overlap = wc.overlap;
  g.point = xi + g.normal * (ri - 0.5 * g.overlap);
  return true;
}

/// A touch continues a slot's contact of the last step when their normals are
/// within 20 degrees (a step turns a normal by far less; the faces of a crease
/// may meet at a few degrees, which the nearest-normal rule tells apart).
inline constexpr double kSameContactCos = 0.9396926207859084;

/// The contacts of a ball with one wall, one per candidate of that wall: a plane
/// or polygon has one candidate; a mesh wall kMeshWallSlots (slot 0 first).
struct WallTouches {
  std::array<ContactPoint, kMeshWallSlots> touch;
  std::array<bool, kMeshWallSlots> has{};    // the slot's candidate touches now
  std::array<bool, kMeshWallSlots> fresh{};  // a new contact in a slot that held another one
  std::uint32_t slots = 1;
};

/// Where a bond between ball a (xa, ra) and ball b acts: the middle of the gap
/// (or overlap) between their surfaces along n (unit, a -> b) at centre distance `dist`.
inline Vec3 bondPoint(const Vec3& xa, double ra, double rb, const Vec3& n, double dist) {
  return xa + n * (ra + 0.5 * (dist - ra - rb));
}

/// Effective radius of two balls (Eq 2-24).
inline double effectiveRadius(double ri, double rj) { return 2.0 * ri * rj / (ri + rj); }

/// What this step has to do besides stepping (decided once, before the forces).
struct StepPlan {
  double kick = 0.0;           // s, the kick's length: dt/2 at the first step, else dt
  bool energy_due = false;     // the watchdog's energy check
  bool network_due = false;    // the contact-network step check
  bool observe = false;        // velocities synchronised to t and the energy are needed
  bool fused = false;          // integration runs inside the contact pass (stage 3)
  bool bonds = false;          // intact bonds to update (stage 4)
};

struct World::Impl {
  // --- the world: constant model, particles, clock
  Model model;
  ParticleState p;
  int threads = 1;
  double time = 0.0;
  std::uint64_t step = 0;
  double dt = 0.0;
  bool half_kick_pending = true;
  // Whether a force pass has run in this World (the touch flags are its): before
  // it, World::touchingContacts goes by the positions.
  bool forces_evaluated = false;
  Vec3 gravity = Vec3::Zero();
  TimestepAudit audit;
  WorldStats stats;
  bool has_clumps = false;
  bool has_mesh_walls = false;  // their contacts take slots (history.wall_normal)
  bool isMember(std::size_t i) const { return has_clumps && p.clump[i] >= 0; }
  // Material-pair constants: ball_ball[a * nm + b], ball_wall[ball * nm + wall].
  std::vector<detail::PairProps> ball_ball, ball_wall;
  std::size_t nm = 0;
  std::vector<detail::WallRuntime> walls;  // pose and activity at t (stage 1)
  std::vector<std::shared_ptr<ForceContribution>> contributions;  // stage 5, in this order

  // --- bonds, parallel and contact (stage 4 writes; saved by exportState); empty without bonds
  struct Bonds {
    // broke[k]: how bond k broke at this step (0: it did not); kActs: its force
    // still acts in this step (a contact bond's shear break, §8.1).
    static constexpr std::uint8_t kTensile = 1, kShear = 2, kActs = 4;
    BondState state;
    std::size_t intact = 0;                   // bonds not yet broken
    std::size_t contact_intact = 0;           // of them contact bonds (their pairs are not in nb.pairs)
    std::vector<std::uint32_t> ball_offset;   // [n+1] rows of ball_end by ball
    std::vector<std::uint32_t> ball_end;      // 2 bond + (0: the ball is a, 1: it is b), by bond
    std::vector<Vec3> force_b;                // [bonds] N, this step's force on b (on a: minus it)
    std::vector<Vec3> torque_a, torque_b;     // [bonds] N m, about each ball's centre
    std::vector<std::uint8_t> broke;          // [bonds] kTensile | kShear | kActs at this step
    std::vector<Vec3> handover_shear;         // [bonds] N, contact bonds only: the shear spring on
                                              // min(a, b) its ordinary contact starts from
    // Contact bonds broken since the last neighbour build: the shear springs their
    // pairs' ordinary contacts start from (taken at the next build; exported).
    std::vector<PairHistory> handover;
    std::vector<BondBreak> breaks;            // every breakage since this World was built
    bool any() const { return state.size() > 0; }
  } bonds;

  // --- neighbour lists (stage 2 writes, stages 3-6 read)
  struct NeighbourLists {
    detail::NeighborFinder finder;
    detail::PairList pairs;                  // ball–ball pairs, canonical CSR
    std::vector<std::uint32_t> wall_offset;  // [n+1] ball–wall candidates in rows by ball
    std::vector<std::uint32_t> wall_index;   // [k] wall of each candidate
    std::vector<std::uint8_t> wall_slot;     // [k] contact slot (mesh walls: 0 .. kMeshWallSlots-1; else 0)
    // Mesh walls: candidate k's triangles within r + skin at the build are
    // wall_triangles[wall_triangle_offset[k] .. [k+1]] (slot 0 of a mesh wall;
    // empty for its other slots and for other walls).
    std::vector<std::uint32_t> wall_triangle_offset;  // [k+1]
    std::vector<std::uint32_t> wall_triangles;  // nearest first
    std::vector<double> wall_triangle_distance;  // m, from the ball at the build
    std::span<const std::uint32_t> trianglesOf(std::uint32_t candidate) const {
      return {wall_triangles.data() + wall_triangle_offset[candidate],
              wall_triangles.data() + wall_triangle_offset[candidate + 1]};
    }
    std::span<const double> triangleDistancesOf(std::uint32_t candidate) const {
      return {wall_triangle_distance.data() + wall_triangle_offset[candidate],
              wall_triangle_distance.data() + wall_triangle_offset[candidate + 1]};
    }
    std::vector<Vec3> ref_position;          // [n] m, positions at the last rebuild
    // [walls] whether each wall was active at the last rebuild: a mesh wall that was,
    // and has not moved since, hands a ball that has not moved either its triangles
    // of then (the same query's answer) instead of a new search of its tree.
    std::vector<std::uint8_t> wall_active_at_build;
    double skin = 0.0;                       // m
    bool need_rebuild = true;
    double last_max_disp2 = 0.0;             // m^2, largest displacement since the rebuild
  } nb;

  // --- contact history (stage 3 writes; carried over by stage 2, saved by exportState)
  struct ContactHistory {
    std::vector<Vec3> pair_shear;            // [pairs] N, shear spring force on i
    std::vector<std::uint8_t> pair_touch;    // [pairs] 1 when touching at this step
    std::vector<Vec3> wall_shear;            // [k] N, on the ball
    std::vector<std::uint8_t> wall_touch;    // [k]
    // [k] unit, a mesh slot's contact normal at the last force pass (zero when
    // free): which touch continues which contact. Empty without mesh walls.
    std::vector<Vec3> wall_normal;
  } history;

  // --- force scratch (stages 3-5 write, 6 and 8 read)
  struct ForceScratch {
    struct CrossSlot {
      Vec3 fi, ti, fj, tj;  // N, N m on the first and the second ball
    };
    std::vector<std::uint32_t> range_begin;  // [team+1] balls of each thread
    // Pairs (i, j) whose j lies in a later range than i: one slot each, in the
    // order of i's rows (ascending i, then ascending j), so a thread meets its
    // slots in its rows in slot order and needs no index per pair.
    std::vector<CrossSlot> cross;
    std::vector<std::uint32_t> cross_begin;  // [team+1] slots of each thread's phase A
    std::vector<std::uint32_t> cross_ball, cross_pair;  // [slots] first ball and pair of each slot
    // The slots each range receives: (second ball, slot) in ascending second
    // ball, then ascending first ball, grouped by the range of the second ball.
    std::vector<std::uint32_t> receive_begin;  // [team+1]
    std::vector<std::uint32_t> receive_ball, receive_slot;  // [slots]
    std::vector<Vec3> acc_force, acc_torque;  // [n] N, N m: contacts and contributions, no gravity
  } scratch;

  // --- observation (stage 6 writes on observed steps)
  struct Observation {
    std::vector<Vec3> velocity, omega;              // [n] synchronised to t
    std::vector<Vec3> clump_velocity, clump_omega;  // [c]
    std::vector<Vec3> clump_force;                  // [c] N, total incl. gravity
    Energy energy;
  } obs;

  // --- watchdog (stage 7)
  struct Guard {
    // dt forced above the automatic step (timestep.allow_unsafe): every step
    // looks for a ball that moved farther than its radius (it can pass through
    // a wall or a ball unseen) and warns (stats.far_travel_*).
    bool check_travel = false;
    bool energy_ref_valid = false;
    double energy_ref = 0.0, energy_scale = 0.0;  // J
    // Work done on each ball by moving walls since the energy reference (J), net
    // and gross (sum of |dW|); empty when no wall moves. Per ball, so the sums do
    // not depend on the number of threads.
    std::vector<double> wall_work, wall_work_gross;
    double wall_work_carried = 0.0;  // J before wall_work's last reset (and from the WorldState)
    std::vector<std::uint8_t> wall_moving;  // [walls] 1 when the wall has a prescribed motion
    detail::SpectrumEstimate spectrum;      // fastest network mode, kept between checks
  } guard;

  // --- relaxation of initial overlaps (Model::relaxation); empty when off or done
  struct Relaxation {
    std::vector<double> pair;  // [pairs] m, initial overlap of the pair (offset at factor 1)
    std::vector<double> wall;  // [k] m, the same for ball–wall candidates
    bool pending = false;      // offsets still to be taken at the first step
    double factor = 0.0;       // offset / initial overlap at this step (1 -> 0, smoothstep)
    // Its own flag, not "pair is not empty": a ball on a wall with no ball pair
    // in the list relaxes too. While on, both arrays match the current lists.
    bool on = false;
    bool active() const { return on; }
    void start(std::size_t pairs, std::size_t walls) {
      pair.assign(pairs, 0.0);
      wall.assign(walls, 0.0);
      on = true;
    }
    void stop() {
      pair.clear();
      pair.shrink_to_fit();
      wall.clear();
      wall.shrink_to_fit();
      on = false;
    }
  } relax;

  // Below this many balls per thread a second thread does not pay: a step of a
  // thousand balls takes tens of microseconds, and waking the team and the
  // barrier cost as much. Since the second range receives its cross-range
  // contributions from a list of its own (assignRanges) instead of scanning every
  // ball's column, 2000 balls run 1.5-2.1x faster on two threads (session 32:
  // the dense and settle benchmark scenes, three runs each); the adaptive team
  // (team_tuner.h) still falls back to one thread where a step is too short.
  // Results are bitwise the same whatever the team.
  static constexpr std::size_t kMinBallsPerThread = 1000;
  int fullTeam() const {
    const auto useful = static_cast<int>(p.size() / kMinBallsPerThread);
    return std::max(1, std::min(threads, useful));
  }
  // The team of this step: the full team or one thread, as the policy (and, when
  // adaptive, the tuner's timing: team_tuner.h) says.
  TeamPolicy team_policy = TeamPolicy::Adaptive;
  detail::TeamTuner tuner;
  bool singleChosen() const {
    return team_policy == TeamPolicy::Single || (team_policy == TeamPolicy::Adaptive && tuner.single());
  }
  int teamSize() const { return singleChosen() ? 1 : fullTeam(); }
  /// The force pass's ranges follow a change of team made between two steps.
  void teamChanged() {
    if (!nb.need_rebuild && !scratch.range_begin.empty()) assignRanges();
  }
  // The bond stage has its own team: a bond costs about a hundred nanoseconds, a
  // few contact evaluations, so a small agglomerate with many bonds pays a second
  // thread where its balls alone would not. 500 bonds a thread (about 50 us of
  // work): the coarse bonded crusher (600 balls, 1,647 bonds) steps 1.35x faster
  // on two threads than on one with a free core (session 37; at 2,000 a thread it
  // ran on one). Bitwise the same whatever the team (bonds.cpp).
  static constexpr std::size_t kMinBondsPerThread = 500;
  int fullBondTeam() const {
    const auto useful = static_cast<int>(bonds.state.size() / kMinBondsPerThread);
    return std::max(fullTeam(), std::min(threads, useful));
  }
  int bondTeamSize() const { return singleChosen() ? 1 : fullBondTeam(); }
  // Whether any stage has a team to choose (the bond team is never smaller than the
  // ball team): the tuner then times the step on it and on one thread (beside a busy
  // process the bonds' second thread made that crusher 1.5x slower than one thread).
  bool teamToChoose() const { return fullBondTeam() > 1; }
  const detail::PairProps& pairProps(std::size_t i, std::size_t j) const {
    return ball_ball[static_cast<std::size_t>(p.material[i]) * nm + static_cast<std::size_t>(p.material[j])];
  }
  const detail::PairProps& wallProps(std::size_t i, std::size_t wall) const {
    return ball_wall[static_cast<std::size_t>(p.material[i]) * nm + static_cast<std::size_t>(model.walls[wall].material)];
  }
  /// The overlap the contact law sees while initial overlaps relax (Model::relaxation).
  double pairOverlap(const ContactPoint& g, std::uint32_t k) const {
    return relax.active() ? relaxedOverlap(g.overlap, relax.factor, relax.pair[k]) : g.overlap;
  }
  double wallOverlap(const ContactPoint& g, std::uint32_t c) const {
    return relax.active() ? relaxedOverlap(g.overlap, relax.factor, relax.wall[c]) : g.overlap;
  }
  /// The contacts of ball i with the wall of candidate c (the first of its
  /// slots), with the walls' poses of `runtime`. A mesh wall's touches go into
  /// the slots whose last normal (history.wall_normal) is nearest to theirs, when
  /// within kSameContactCos, and the rest into free slots, lowest first: a
  /// contact keeps its shear spring while the ball moves along a crease.
  [[gnu::always_inline]] void wallTouches(const std::vector<detail::WallRuntime>& runtime, std::size_t i,
                                          std::uint32_t c, WallTouches& out) const {
    const std::uint32_t wk = nb.wall_index[c];
    if (model.walls[wk].shape == WallShape::Mesh) return meshWallTouches(runtime[wk], i, c, out, false);
    out.slots = 1;
    out.fresh[0] = false;
    out.has[0] = ballWallTouch(runtime[wk], model.walls[wk], p.position[i], p.radius[i], out.touch[0]);
  }
  /// A mesh wall's part of wallTouches (wall_touches.cpp). `bounded`: skip the
  /// triangles that cannot be touched, from the ball's distance moved since the
  /// neighbour build (the force pass, which alone may assume it is under the skin).
  void meshWallTouches(const detail::WallRuntime& runtime, std::size_t i, std::uint32_t c, WallTouches& out,
                       bool bounded) const;
  /// Calls visit(c, wall, touch or nullptr) for every wall candidate of ball i.
  template <class Visit>
  void forEachWallTouch(const std::vector<detail::WallRuntime>& runtime, std::size_t i, Visit&& visit) const {
    WallTouches t;
    for (std::uint32_t c = nb.wall_offset[i]; c < nb.wall_offset[i + 1]; c += t.slots) {
      wallTouches(runtime, i, c, t);
      for (std::uint32_t s = 0; s < t.slots; ++s) visit(c + s, nb.wall_index[c], t.has[s] ? &t.touch[s] : nullptr);
    }
  }
  double& stageSeconds(Stage s) { return stats.stage_seconds[static_cast<std::size_t>(s)]; }

  // Set-up (world_setup.cpp).
  void initialise(int requested_threads);
  void buildPairProps();
  /// Members' positions, velocities and spins from their body's; returns the
  /// largest squared displacement of a member since the last rebuild (m^2; 0 before one).
  double placeMembers(std::size_t c);
  /// The same from the body's state given (the integrator's registers: reading
  /// back what it just stored stalls on store forwarding).
  double placeMembers(std::size_t c, const Quat& q, const Vec3& centre, const Vec3& v, const Vec3& L);
  void restoreHistory(const WorldState& state);

  // One step (world.cpp): the stages in order.
  void doStep(const std::function<void(const Snapshot&)>& observer);
  StepPlan planStep(bool observed) const;

  // 1. prepare (stages/prepare.cpp)
  void prepareStage();
  // 2. neighbours (stages/neighbours.cpp, stages/relaxation.cpp)
  void neighbourStage();
  void rebuildNeighbours();
  void assignRanges();
  void startRelaxation();
  void updateRelaxation();
  // 3. forces (stages/forces.cpp: the contact law and the pass in one unit, so it inlines)
  void forceStage(const StepPlan& plan, StepChecks& checks);
  template <class Law> void addWallForces(std::size_t i, Vec3& f, Vec3& t, StepChecks& c);
  template <class Law> void forcePass(bool integrate_now, double h, StepChecks& merged);
  // 4. bonds (stages/bonds.cpp; contact bonds in stages/contact_bonds.cpp)
  void bondStage(StepChecks& checks);
  // The intact parallel bonds k[0 .. lanes of R) through the bond law (bond_law.h).
  template <class R> bool stepParallelBonds(const std::size_t* k, const bond_law::BondConstants& law);
  template <class Law> std::uint8_t contactBondStep(std::size_t k, StepChecks& c);
  std::uint8_t contactBondStepAny(std::size_t k, StepChecks& c);
  void installContactBond(std::size_t k);
  std::vector<std::uint64_t> contactBondedPairs() const;
  void takeHandovers();
  double contactBondEnergy(std::size_t k) const;
  NetworkSpring contactBondSpring(std::size_t k) const;
  void installBonds(const std::vector<BondSpec>& specs);
  void indexBonds();
  double bondEnergy() const;
  void bondSprings(std::vector<NetworkSpring>& out) const;
  // 5. extra forces (stages/extra_forces.cpp)
  void extraForceStage();
  ForceInput forceInput() const { return ForceInput{time, dt, p}; }
  // 6. observe (stages/observe.cpp, stages/energy.cpp)
  void observeStage();
  Snapshot snapshot(std::vector<Vec3>& total_force, std::vector<std::uint8_t>& wall_active) const;
  void clumpLoad(std::size_t c, Vec3& force, Vec3& torque) const;
  Energy energyAny(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const;
  template <class Law> Energy energy(const std::vector<Vec3>& v, const std::vector<Vec3>& w) const;
  // 7. watchdog (stages/watchdog.cpp, stages/network_check.cpp)
  void watchdogStage(const StepPlan& plan, const StepChecks& checks);
  void checkOverlap(const StepChecks& checks) const;
  void checkFinite() const;
  void checkTravel();
  void checkEnergy(const Energy& e);
  bool energyCheckApplies() const;
  void checkNetworkStep();
  std::vector<std::int32_t> networkBodies(detail::ContactNetwork& net) const;
  template <class Law>
  void visitTouchingContacts(const std::vector<std::int32_t>& body_of, const detail::ContactVisitor& visit) const;
  std::string stepAdvice() const;
  // On demand (contact_measures.cpp): World::particleStress, World::wallForces.
  template <class Law, class PairVisit, class WallVisit>
  void forEachElasticContact(PairVisit&& pair, WallVisit&& wall, bool by_geometry = false) const;
  template <class Law> void contactStress(std::vector<geometry::Mat3>& sum) const;
  template <class Law> std::vector<Vec3> wallLoads() const;
  template <class Law> TouchingContacts touching() const;
  // 8. integrate (stages/integrate.cpp; integrate() below is also fused into stage 3)
  void integrateStage(const StepPlan& plan, StepChecks& checks);
  void integrate(std::size_t i, const Vec3& f_contact, const Vec3& torque, double h, StepChecks& c);
  void integrateClumps(double h, StepChecks& merged);
  void finishStep(const StepChecks& checks);
};

/// Kick and drift of one free ball (Eq 2-11..2-13, local damping Eq 2-15).
/// Inline: the contact pass (stage 3) fuses it on unobserved steps.
[[gnu::always_inline]] inline void World::Impl::integrate(std::size_t i, const Vec3& f_contact, const Vec3& torque,
                                                         double h, StepChecks& c) {
  const double inv_m = p.inv_mass[i];
  Vec3 f = f_contact + gravity / inv_m;  // generalised force incl. gravity (Eq 2-14)
  Vec3 t = torque;
  // The new state is formed in registers and checked there, then stored once:
  // reading back what was just stored (a 16- plus an 8-byte store read as
  // doubles) stalled on store forwarding and cost a third of a sparse scene's step.
  Vec3 v = p.velocity[i], w = p.omega[i];
  const double alpha = model.contact.local_damping;
  if (alpha > 0) {
    // Cundall's local damping, Eq 2-15 in its sign form: -alpha |F| sign(v) per component.
    for (int a = 0; a < 3; ++a) {
      f[a] -= alpha * std::abs(f[a]) * ((v[a] > 0) - (v[a] < 0));
      t[a] -= alpha * std::abs(t[a]) * ((w[a] > 0) - (w[a] < 0));
    }
  }
  v += (h * inv_m) * f;                   // Eq 2-11
  w += (h * p.inv_inertia[i]) * t;        // Eq 2-12 (sphere: no gyroscopic term)
  const Vec3 x = p.position[i] + dt * v;  // Eq 2-13
  if (!x.allFinite() || !v.allFinite()) c.non_finite = true;
  c.max_disp2 = std::max(c.max_disp2, (x - nb.ref_position[i]).squaredNorm());
  p.velocity[i] = v;
  p.omega[i] = w;
  p.position[i] = x;
}

}  // namespace rocklab::sim
