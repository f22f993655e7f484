#pragma once
// World = constant Model + mutable state. One call of step() runs the stages
// below in this order (World::Impl::doStep in src/world.cpp, one call each; each
// stage's body is in a file of its own in src/stages/, and its wall time is in
// WorldStats::stage_seconds):
//
//   1. prepare       gravity schedule, wall poses and activity at t; is a
//                    neighbour rebuild due (a body or wall moved > skin/2)?
//   2. neighbours    rebuild pair and wall-candidate lists when due (history
//                    carried over); relaxation offsets of initial overlaps
//   3. forces        contact law at every pair and wall contact, summed per ball
//                    in a fixed order; on steps that nothing observes, with no
//                    intact bonds and no force contributions, fused with the
//                    kick and drift (stage 8)
//   4. bonds         parallel and contact bonds (bonds.h): update, breakage, forces
//                    and moments into the accumulators; only when the world has bonds
//   5. extra forces  force contributions (force_contribution.h) add into the
//                    accumulators in a fixed order; only when present
//   6. observe       only on observed steps: velocities synchronised to t, energy
//   7. watchdog      overlap limit (every step); energy growth and the contact
//                    network's step when due (observed steps)
//   8. integrate     leapfrog kick and drift (Eq 2-11..2-13), local damping,
//                    clumps as rigid bodies (Eq 2-44..2-46); clock; NaN guard
//
// The observer is called between stages 7 and 8 with the whole-step snapshot.
// Threads: stages 2, 3, 4 and 8 run over balls (bonds) with OpenMP static
// schedules; every ball's sums are formed in the same order whatever the number
// of threads.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "rocklab/sim/bonds.h"
#include "rocklab/sim/force_contribution.h"
#include "rocklab/sim/model.h"
#include "rocklab/sim/particles.h"
#include "rocklab/sim/snapshot.h"
#include "rocklab/sim/timestep.h"

namespace rocklab::sim {

/// Thrown when the stability watchdog stops a run. The message names the body,
/// the time and the setting to change.
struct WatchdogError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Contact history of one ball–ball pair (by particle index, i < j).
struct PairHistory {
  std::uint32_t i = 0, j = 0;
  Vec3 shear = Vec3::Zero();  // N, shear spring force on i
  double relax_offset = 0.0;  // m, initial overlap still being relaxed (Model::relaxation)
};
/// A mesh wall has this many contact slots per ball near it: a ball in a concave
/// crease or corner of one mesh touches it at two or three places
/// (TriangleMeshIndex::touches), each a contact with its own shear spring. The
/// nearest three are kept.
inline constexpr std::uint32_t kMeshWallSlots = 3;
/// Contact history of one ball–wall contact.
struct WallHistory {
  std::uint32_t particle = 0, wall = 0;
  Vec3 shear = Vec3::Zero();  // N, shear spring force on the ball
  double relax_offset = 0.0;  // m, initial overlap still being relaxed (Model::relaxation)
  // A mesh wall: which of the ball's contacts with it (0, 1, 2: a ball in a
  // crease touches a mesh twice) and that contact's last unit normal (which
  // touch continues it). 0 and zero for other walls.
  std::uint32_t slot = 0;
  Vec3 normal = Vec3::Zero();
};

/// Everything that changes during a run: with the Model it restarts a run bit
/// for bit.
struct WorldState {
  double time = 0.0;          // s
  std::uint64_t step = 0;
  double dt = 0.0;            // s
  bool half_kick_pending = true;  // first kick is dt/2 (velocities given at t = 0)
  ParticleState particles;
  std::vector<PairHistory> pair_history;
  std::vector<WallHistory> wall_history;
  BondState bonds;  // every bond, intact and broken; empty without bonds
  // J, World::movingWallWork() when exported: a World built from the state goes on
  // counting from it (an experiment that rebuilds its World keeps the total), and
  // so does a restart (checkpoints keep it).
  double moving_wall_work = 0.0;
};

/// The stages of one step, in their order (see the head of this file).
enum class Stage { Prepare, Neighbours, Forces, Bonds, ExtraForces, Observe, Watchdog, Integrate, Count };
inline constexpr std::size_t kStageCount = static_cast<std::size_t>(Stage::Count);
/// Stage names as results.json reports them ("prepare", "extra_forces", ...).
const char* stageName(Stage s);

struct WorldStats {
  std::uint64_t neighbour_rebuilds = 0;
  std::size_t pairs_in_list = 0;
  std::size_t wall_candidates = 0;  // balls near a wall, counted once a wall (a mesh wall has slots)
  double neighbour_seconds = 0.0;  // s of wall time spent in neighbour-list rebuilds
  std::uint64_t network_checks = 0;  // step checks of the contact network done
  double network_step_ratio = 0.0;   // largest dt / (stable step of the network) they found; stops above 1
  std::array<double, kStageCount> stage_seconds{};  // s of wall time per Stage (index = Stage)
  // Only with a dt forced above the automatic step (timestep.allow_unsafe): steps
  // in which a ball moved farther than its radius (it can pass through a wall or a
  // ball unseen), and the first of them described (ball, time, distance).
  std::uint64_t far_travel_steps = 0;
  std::string far_travel;
  // TeamPolicy::Adaptive (a team of two or more): timing probes of the other
  // team, switches between the full team and one thread, and steps run on one.
  std::uint64_t team_probes = 0;
  std::uint64_t team_switches = 0;
  std::uint64_t single_thread_steps = 0;
};

/// The threads a step runs on. Results are bitwise the same on any team, so this
/// decides only the wall time. Adaptive (the default) times the full team
/// against one thread now and then and runs on the faster: one thread wins when
/// another process holds a core (sim/src/team_tuner.h). Full and Single pin it.
enum class TeamPolicy { Adaptive, Full, Single };

/// The contacts that touch (overlap > 0) in the state at the current time: ball
/// pairs (first < second) and ball–wall contacts (ball, wall index), each with
/// its overlap (m, the one the contact law sees) and the elastic energy its
/// springs store (J, normal and shear, at the World's law and stiffnesses: the
/// energy log's per-contact term).
struct TouchingContacts {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  std::vector<double> pair_overlap;
  std::vector<double> pair_energy;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> walls;
  std::vector<double> wall_overlap;
  std::vector<double> wall_energy;
};

class World {
 public:
  /// Builds a world; validates the model, audits the time step (throws
  /// std::invalid_argument with the reason when the model or dt is unusable).
  World(Model model, const std::vector<SphereSpec>& spheres, int threads = 0);
  /// The same with rigid clumps; their member balls follow the free spheres.
  World(Model model, const std::vector<SphereSpec>& spheres, const std::vector<ClumpSpec>& clumps,
        int threads = 0);
  /// The same with bonds between its balls: parallel ones (Model::bonds) installed
  /// stress-free where the balls are now, contact ones (BondKind::Contact) with the
  /// pair's contact force there (bonds.h). Throws std::invalid_argument for a bad bond.
  World(Model model, const std::vector<SphereSpec>& spheres, const std::vector<ClumpSpec>& clumps,
        const std::vector<BondSpec>& bonds, int threads = 0);
  /// Restarts from a saved state (dt is taken from the state).
  World(Model model, WorldState state, int threads = 0);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Advances one step. When `observer` is given it is called at time t with a
  /// synchronised snapshot (energy included) before the kick. Throws WatchdogError.
  void step(const std::function<void(const Snapshot&)>& observer = {});

  double time() const;
  std::uint64_t stepCount() const;
  double dt() const;
  const Model& model() const;
  const ParticleState& particles() const;
  const TimestepAudit& timestepAudit() const;
  const WorldStats& stats() const;
  /// Threads the next step uses: the full team, or one where the team policy
  /// (setTeamPolicy) chose one thread.
  int threads() const;
  /// The full team: the requested threads, fewer for small worlds.
  int fullTeam() const;
  /// TeamPolicy::Adaptive unless set; takes effect at the next step.
  void setTeamPolicy(TeamPolicy policy);
  /// Threads the bond stage uses: as many as threads(), more for many bonds.
  int bondThreads() const;
  Vec3 gravity() const;
  /// Every bond, intact and broken, as of the last step.
  const BondState& bonds() const;
  std::size_t intactBonds() const;
  /// Every breakage since this World was built, in the order they happened
  /// (within a step by bond index).
  const std::vector<BondBreak>& bondBreaks() const;
  /// Average stress of every ball (Pa, compression positive, dem-models §11):
  /// -(1/V) sum over its contacts and intact bonds of sym(x_c (x) F_c), with
  /// V = 4/3 pi R^3, x_c from the centre to the contact point and F_c the
  /// elastic contact force (normal and shear springs, no dashpots) or the bond
  /// force of the last step. Computed on demand (not in the step).
  std::vector<geometry::Mat3> particleStress() const;
  /// Force (N) the balls exert on each wall (index = Model::walls), from the
  /// elastic contact forces of the last step (no dashpots: with contact damping
  /// the dashpots' share is left out). A platen's load cell.
  std::vector<Vec3> wallForces() const;
  /// Which balls touch which balls and walls, from the contacts of the last step
  /// (the ones particleStress sums). Before the first step: none in a World built
  /// from spheres; in one built from a saved state, the pairs and walls its
  /// positions overlap (what the first step's force pass will find), with the
  /// saved shear springs. The crusher's freeze tells load-bearing neighbours from
  /// loose ones with it, and bounds what a crowded breakage hands back by its energies.
  TouchingContacts touchingContacts() const;
  /// Work (J) the moving walls have done on the balls (WorldState::moving_wall_work
  /// says since when): every step, each wall contact's force, dashpots included,
  /// times the wall's velocity at the contact; summed in ball order, so the same on
  /// any number of threads. 0 without a moving wall. A crusher's mantle energy.
  double movingWallWork() const;

  /// Adds forces other than contacts (force_contribution.h); called in the
  /// `extra forces` stage in the order added. A world with contributions no
  /// longer fuses integration into the contact pass.
  void addForceContribution(std::shared_ptr<ForceContribution> contribution);

  /// Saves everything needed to continue bit for bit.
  WorldState exportState() const;
  /// FNV-1a hash of positions, velocities and spins: equal hashes mean equal states.
  std::uint64_t stateHash() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Removes balls from a saved state, together with the whole clump of any
/// removed member and every bond of a removed ball; indices in the contact
/// history and the bonds are renumbered and ids kept.
/// A World rebuilt from the result (World(model, state)) continues the run
/// without them: this is how experiments drop discharged pebbles or the clumps
/// cut by a plate added after deposition.
WorldState withoutBalls(WorldState state, std::vector<bool> remove);

/// Mass (kg) of a solid sphere of `radius` (m) at `density` (kg/m^3).
inline double sphereMass(double density, double radius) {
  return density * 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
}

/// Sets ball `i`'s mass and what follows from it for a free sphere: 1/m and
/// 1/(2/5 m R^2) (Eq 2-8).
void setFreeSphereMass(ParticleState& particles, std::size_t i, double mass);

/// Appends a free sphere (no clump) of `mass` and `id` to the balls, the way the
/// World builds its spheres; returns its row. Experiments add balls to a saved
/// state with it (the crusher's fragments).
std::uint32_t appendFreeSphere(ParticleState& particles, const SphereSpec& sphere, double mass, std::uint64_t id);

/// Validates a model, its spheres and clumps; returns "" or a message naming the field.
std::string validateModel(const Model& model, const std::vector<SphereSpec>& spheres,
                          const std::vector<ClumpSpec>& clumps = {});

}  // namespace rocklab::sim
