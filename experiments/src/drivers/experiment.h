#pragma once
// Experiment drivers: what a scene's [experiment] table asks for besides
// stepping — phases (deposit, tilt, open the gate), measurements and the end
// condition. The run loop (run.cpp) calls advance() between steps; a phase
// switch rebuilds the World from its exported state with an edited Model
// (gravity turned, a wall removed or added, bodies deleted), so the engine
// keeps a constant Model and the contact history survives the switch.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "rocklab/experiments/scene.h"
#include "rocklab/sim/world.h"

namespace rocklab::experiments {

struct ExperimentContext {
  int threads = 0;
  std::ostream* log = nullptr;
};

class Experiment {
 public:
  virtual ~Experiment() = default;
  /// True when the coming step should hand its snapshot to observe().
  virtual bool wantsSnapshot(std::uint64_t /*step*/) const { return false; }
  virtual void observe(const sim::Snapshot& /*s*/) {}
  /// Called before every step; may replace the world. False = the experiment is over.
  virtual bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) = 0;
  /// Ids of the marker bodies (drawn red by the cameras).
  virtual std::unordered_set<std::uint64_t> markerBodies() const { return {}; }
  /// Name of the camera whose raw frames the experiment wants (tracking), "" = none.
  virtual std::string trackingCamera() const { return {}; }
  virtual void cameraFrame(std::uint64_t /*frame*/, double /*time*/, const cv::Mat& /*raw*/) {}
  /// A few words for the progress line, e.g. "phase flow, 812 bodies left".
  virtual std::string progress() const { return {}; }
  /// True when the last advance() was cut short by a stop request (Ctrl-C, SIGTERM)
  /// and left the driver and the World as they were before it: the run stops
  /// before stepping, so a restart advances this step again, as an uninterrupted
  /// run did.
  virtual bool advanceUndone() const { return false; }
  /// True when the advance() that returned false ended the experiment at a state
  /// to restart from (a chute's settled deposit, experiment.stop_after): the run
  /// stops before stepping, so its last checkpoint is that state and a restart
  /// goes on from it as the straight run did.
  virtual bool endsBeforeStep() const { return false; }
  /// Restart (`rocklab restart`): whether the driver saves its own state in
  /// checkpoint.h5 and goes on from it; a restart of one that cannot is refused.
  virtual bool restartable() const { return false; }
  /// The driver's state between two steps (a restartable driver).
  virtual nlohmann::json saveState() const { return nullptr; }
  /// Puts back what saveState gave, before the World is rebuilt from the
  /// checkpoint, and adds to `model` (the scene's) what the run had added to its
  /// own (a breakage's fragment materials). Throws std::invalid_argument or
  /// nlohmann::json::exception when the state does not fit.
  virtual void restoreState(const nlohmann::json& /*state*/, sim::Model& /*model*/) {}
  /// Adds the figures to results.json and writes the experiment's CSV and PNG files.
  virtual void report(nlohmann::json& results, const std::filesystem::path& out_dir,
                      std::ostream& log) = 0;
};

/// The driver for scene.experiment_type, or null for a plain run (drivers/registry.cpp).
std::unique_ptr<Experiment> makeExperiment(const Scene& scene);

// ---- helpers shared by the drivers

/// One rigid body of a world: a free sphere (ball index) or a clump.
struct BodyRef {
  bool clump = false;
  std::uint32_t index = 0;  // ball index for a sphere, clump index for a clump
};

/// Every body of a world by its stable id (sphere ids and clump ids share one space).
std::unordered_map<std::uint64_t, BodyRef> indexBodies(const sim::ParticleState& p);
/// Centre of mass and mass of a body.
geometry::Vec3 bodyPosition(const sim::ParticleState& p, const BodyRef& b);
double bodyMass(const sim::ParticleState& p, const BodyRef& b);
/// Largest ball speed (members included, so spin counts too), m/s; balls with
/// skip[i] (when skip is given) do not count.
double maxBallSpeed(const sim::ParticleState& p, const std::vector<bool>& skip = {});
/// Gravity of magnitude g tilted by `angle_deg` towards -x (the chute outlet):
/// rotated (|g| kept) or with the study's additional component g tan(angle).
geometry::Vec3 tiltedGravity(double g, double angle_deg, bool rotate);
/// Index of the wall called `name` (the scene reader checked that it exists).
std::size_t wallIndex(const sim::Model& model, const std::string& name);

/// Rebuilds `world` from its state after `edit` changed a copy of the model and
/// `remove` (one flag per ball, may be empty) deleted bodies.
void switchPhase(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx,
                 const std::function<void(sim::Model&)>& edit,
                 const std::vector<bool>& remove = {});

/// Rebuilds `world` after `edit` changed a copy of its state (the model kept).
void switchState(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx,
                 const std::function<void(sim::WorldState&)>& edit);

/// The most steps a run counts: t = step dt is exact in a double up to 2^53.
inline constexpr double kMaxSteps = 9007199254740992.0;

/// Steps in `interval` s at the step `dt` (at least 1): an interval longer than
/// any run (more than 2^53 steps) counts as 2^53, never as an overflow.
std::uint64_t stepsIn(double interval, double dt);

}  // namespace rocklab::experiments
