#pragma once
// World = constant Model + mutable state. One call of step() advances one time
// step through named stages:
//
//   1. prepare      gravity schedule, wall poses and activity at t   (reads time)
//   2. neighbours   rebuild the pair and wall-candidate lists when some body
//                   moved more than half the skin; history carried over
//   3. contacts     force–displacement law at every pair and wall contact
//                   (reads x, v, omega at t - dt/2; writes pair slots, shear history)
//   4. gather       sum each ball's contact forces in a fixed order (bitwise
//                   identical for any thread count)
//   5. observe      only on steps an observer asked for: synchronised snapshot
//   6. integrate    leapfrog kick and drift (Eq 2-11..2-13), NaN guard; clumps
//                   sum their members' forces and moments (Eq 2-44, 2-46) and
//                   move as rigid bodies (src/rigid_body.h), members follow
//   7. watchdog     overlap limit every step, energy every check_interval steps
//
// Threads: stages 3, 4 and 6 run over balls with OpenMP static schedules; every
// ball's sums are formed in the same order whatever the number of threads.
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

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
/// Contact history of one ball–wall contact.
struct WallHistory {
  std::uint32_t particle = 0, wall = 0;
  Vec3 shear = Vec3::Zero();  // N, shear spring force on the ball
  double relax_offset = 0.0;  // m, initial overlap still being relaxed (Model::relaxation)
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
};

struct WorldStats {
  std::uint64_t neighbour_rebuilds = 0;
  std::size_t pairs_in_list = 0;
  std::size_t wall_candidates = 0;
  double neighbour_seconds = 0.0;  // s of wall time spent in neighbour-list rebuilds
  std::uint64_t network_checks = 0;  // step checks of the contact network done
  double network_step_ratio = 0.0;   // largest dt / (stable step of the network) they found; stops above 1
};

class World {
 public:
  /// Builds a world; validates the model, audits the time step (throws
  /// std::invalid_argument with the reason when the model or dt is unusable).
  World(Model model, const std::vector<SphereSpec>& spheres, int threads = 0);
  /// The same with rigid clumps; their member balls follow the free spheres.
  World(Model model, const std::vector<SphereSpec>& spheres, const std::vector<ClumpSpec>& clumps,
        int threads = 0);
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
  /// Threads the step really uses: the requested ones, fewer for small worlds.
  int threads() const;
  Vec3 gravity() const;

  /// Saves everything needed to continue bit for bit.
  WorldState exportState() const;
  /// FNV-1a hash of positions, velocities and spins: equal hashes mean equal states.
  std::uint64_t stateHash() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Removes balls from a saved state, together with the whole clump of any
/// removed member; indices in the contact history are renumbered and ids kept.
/// A World rebuilt from the result (World(model, state)) continues the run
/// without them: this is how experiments drop discharged pebbles or the clumps
/// cut by a plate added after deposition.
WorldState withoutBalls(WorldState state, std::vector<bool> remove);

/// Validates a model, its spheres and clumps; returns "" or a message naming the field.
std::string validateModel(const Model& model, const std::vector<SphereSpec>& spheres,
                          const std::vector<ClumpSpec>& clumps = {});

}  // namespace rocklab::sim
