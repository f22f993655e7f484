// Set-up of a run (run_internal.h): everything that can fail on bad input
// happens here, before anything is written to the output directory.
#include <algorithm>
#include <cmath>
#include <ostream>
#include <sstream>

#include "rocklab/sim/output/checkpoint.h"
#include "run/output_folder.h"
#include "run/run_internal.h"

namespace rocklab::experiments::detail {

namespace {

namespace out = sim::output;

/// Puts `experiment` back where the checkpoint's /experiment left it, adding to
/// `model` what the run had added; "" or what is wrong, naming the dataset.
std::string restoreExperiment(const Scene& scene, const std::vector<std::uint8_t>& bytes, Experiment& experiment,
                              sim::Model& model) {
  const std::string type = "experiment." + scene.experiment_type;
  if (!experiment.restartable())
    return type + " scenes cannot be restarted from a checkpoint yet (the experiment's phase is not saved; "
                  "restartable: experiment.crusher and experiment.chute); run the scene again";
  if (bytes.empty())
    return "holds no /experiment (the state of the " + type +
           " driver: written by a run of another scene, or by a rocklab before experiment restarts); run the "
           "scene again";
  try {
    const nlohmann::json saved = nlohmann::json::from_cbor(bytes);
    const std::string saved_type = saved.at("experiment").get<std::string>();
    const int format = saved.at("format").get<int>();
    if (saved_type != scene.experiment_type)
      return "dataset /experiment: saved by experiment." + saved_type + ", the scene is " + type;
    if (format != kExperimentStateFormat)
      return "dataset /experiment: format " + std::to_string(format) + " (this build reads " +
             std::to_string(kExperimentStateFormat) + ")";
    experiment.restoreState(saved.at("state"), model);
  } catch (const nlohmann::json::exception& e) {
    return "dataset /experiment: not the state of the " + type + " driver this build saves (" + e.what() + ")";
  } catch (const std::invalid_argument& e) {
    return "dataset /experiment: " + std::string(e.what());
  }
  return {};
}

/// The World (and the experiment, when the scene has one) where the checkpoint
/// options.restart left it; every value of the file is checked (World(Model,
/// WorldState)) and a complaint names the file.
int restartWorld(const Scene& scene, const RunOptions& options, std::ostream& log, RunSetup& setup) {
  const std::string file = "checkpoint '" + options.restart.string() + "': ";
  std::unique_ptr<sim::World>& world = setup.world;
  try {
    out::Checkpoint cp = out::readCheckpoint(options.restart);
    if (cp.unchecked > 0)
      log << "warning: " << file << cp.unchecked
          << " datasets have no checksum (written before rocklab stored them): read unchecked\n";
    sim::Model model = scene.model;
    if (setup.experiment) {
      if (const std::string bad = restoreExperiment(scene, cp.experiment_state, *setup.experiment, model);
          !bad.empty()) {
        log << "error: " << file << bad << "\n";
        return kExitBadInput;
      }
    }
    world = std::make_unique<sim::World>(model, std::move(cp.state), options.threads);
    setup.earlier_wall_s = cp.run_wall_time_s;
  } catch (const out::CheckpointError& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    log << "error: " << file << e.what() << "\n";
    return kExitBadInput;
  }
  // The saved step against the scene's stable one: a larger dt than this scene
  // allows (a damaged value, or stiffer contacts set for the restart) blows up.
  const sim::TimestepAudit& audit = world->timestepAudit();
  if (!scene.model.timestep.allow_unsafe && world->dt() > audit.automatic * (1 + 1e-12)) {
    log << "error: " << file << "attribute dt: " << world->dt() << " s (allowed: > 0 s, at most the automatic step "
        << audit.automatic << " s of the scene as restarted, or timestep.allow_unsafe = true)\n";
    return kExitBadInput;
  }
  return kExitOk;
}

/// The World at t = 0 from the scene, or where options.restart left it.
int makeWorld(const Scene& scene, const RunOptions& options, std::ostream& log, RunSetup& setup) {
  if (!options.restart.empty()) return restartWorld(scene, options, log, setup);
  try {
    setup.world = std::make_unique<sim::World>(scene.model, scene.spheres, scene.clumps, scene.bonds, options.threads);
  } catch (const std::invalid_argument& e) {
    log << "error: " << (scene.source.empty() ? std::string("scene") : scene.source.string())
        << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  return kExitOk;
}

/// Step counts of the scene's end and of its output intervals at the World's dt;
/// "" or why the end cannot be counted in steps (an end_time or dt that
/// overflows the count), naming the keys and their values.
std::string countSteps(const Scene& scene, double dt, bool restart, RunSetup& setup) {
  setup.dt = dt;
  std::ostringstream e;
  if (scene.run.steps > 0) {
    if (static_cast<double>(scene.run.steps) > kMaxSteps) {
      e << "scene.steps = " << scene.run.steps << ": more than 2^53 = 9.007e15, the most steps a run counts";
      return e.str();
    }
    setup.total_steps = scene.run.steps;
  } else {
    const double steps = scene.run.end_time / dt;
    if (!(steps <= kMaxSteps)) {
      e << "scene.end_time = " << scene.run.end_time << " s is " << steps << " steps of dt = " << dt << " s ("
        << (restart                      ? "the checkpoint's step"
            : scene.model.timestep.dt > 0 ? "timestep.dt"
                                          : "the automatic step")
        << "): more than 2^53 = 9.007e15, the most steps a run counts; lower scene.end_time"
        << (!restart && scene.model.timestep.dt > 0 ? " or raise timestep.dt" : "");
      return e.str();
    }
    setup.total_steps = static_cast<std::uint64_t>(std::llround(steps));
  }
  // An interval longer than the run is never reached: capped, not refused.
  auto stepsFor = [dt](double interval) -> std::uint64_t { return interval > 0 ? stepsIn(interval, dt) : 0; };
  setup.frame_every = stepsFor(scene.run.frame_interval);
  setup.energy_every = stepsFor(scene.run.energy_interval);
  setup.checkpoint_every = stepsFor(scene.run.checkpoint_interval);
  return {};
}

/// Active modules: what this scene constructs (and so pays for), for the log and results.json.
std::vector<std::string> activeModules(const Scene& scene, const sim::World& world,
                                       bool has_experiment) {
  const sim::Model& model = world.model();
  std::vector<std::string> modules;
  modules.push_back(model.contact.law == sim::ContactLaw::Linear ? "contact:linear"
                                                                 : "contact:hertz_mindlin");
  if (model.contact.damping_normal > 0 || model.contact.damping_shear > 0)
    modules.push_back("damping:viscous");
  if (model.contact.local_damping > 0) modules.push_back("damping:local");
  const std::pair<sim::WallShape, const char*> shapes[] = {
      {sim::WallShape::Plane, "walls:plane"},
      {sim::WallShape::Polygon, "walls:polygon"},
      {sim::WallShape::Mesh, "walls:mesh"}};
  auto anyWall = [&model](auto predicate) {
    return std::any_of(model.walls.begin(), model.walls.end(), predicate);
  };
  for (const auto& [shape, name] : shapes)
    if (anyWall([shape = shape](const sim::Wall& w) { return w.shape == shape; }))
      modules.push_back(name);
  if (anyWall([](const sim::Wall& w) { return !w.motion.isStatic(); }))
    modules.push_back("walls:moving");
  if (!model.gravity_changes.empty()) modules.push_back("gravity:schedule");
  if (world.particles().clumps.size() > 0) modules.push_back("clumps");
  for (const sim::BondKind kind : {sim::BondKind::Parallel, sim::BondKind::Contact}) {
    const auto& k = world.bonds().kind;
    if (std::find(k.begin(), k.end(), static_cast<std::uint8_t>(kind)) != k.end())
      modules.push_back(std::string("bonds:") + sim::bondKindName(kind));
  }
  if (has_experiment) modules.push_back("experiment:" + scene.experiment_type);
  if (!scene.cameras.empty())
    modules.push_back("render:" + std::to_string(scene.cameras.size()) + " camera(s)");
  if (scene.run.hdf5) modules.push_back("output:hdf5");
  if (scene.run.vtk) modules.push_back("output:vtk");
  if (scene.run.checkpoint) modules.push_back("output:checkpoint");
  return modules;
}

/// The set-up lines of the log: scene, modules, clump shapes, time-step audit, steps.
void logSetup(const Scene& scene, const RunSetup& setup, const RunOptions& options,
              std::ostream& log) {
  const sim::World& world = *setup.world;
  const sim::Model& model = world.model();
  log << "rocklab: scene '" << scene.run.name << "'"
      << (options.restart.empty() ? "" : " (restart)") << ", " << world.particles().size()
      << " balls (" << world.particles().clumps.size() << " clumps), " << model.walls.size()
      << " walls, threads: " << world.fullTeam() << "\n";
  log << "  modules: ";
  for (std::size_t k = 0; k < setup.modules.size(); ++k) log << (k ? ", " : "") << setup.modules[k];
  log << "\n";
  for (const ClumpShapeReport& c : scene.clump_shapes)
    log << "  clump shape of " << c.source << ": " << c.shape << ", " << c.members
        << " members, mass " << c.mass * 1e3 << " g (" << c.distribution
        << " distribution), volume " << c.volume * 1e9 << " mm^3 (equivalent diameter "
        << c.equivalent_diameter * 1e3 << " mm); true union volume " << c.union_volume * 1e9
        << " +- " << c.union_volume_error * 1e9 << " mm^3\n";
  log << world.timestepAudit().describe(model.timestep) << "\n";
  log << "  steps: " << setup.total_steps << " from t = " << world.time() << " s, output to "
      << options.out_dir.string() << "\n";
}

/// The scene's cameras (the GL context is made here, only when there is one),
/// the experiment's tracking camera handing it its raw frames.
int makeCameras(const Scene& scene, const RunOptions& options, std::ostream& log, RunSetup& setup) {
  try {
    for (const CameraSettings& c : scene.cameras)
      setup.cameras.push_back(std::make_unique<CameraRecorder>(c, scene, options.out_dir, log));
  } catch (const std::exception& e) {
    log << "error: camera: " << e.what() << "\n";
    return kExitBadInput;
  }
  Experiment* experiment = setup.experiment.get();
  if (experiment && !experiment->trackingCamera().empty())
    for (auto& c : setup.cameras)
      if (c->settings().name == experiment->trackingCamera())
        c->on_frame = [experiment](std::uint64_t frame, double time, const cv::Mat& raw) {
          experiment->cameraFrame(frame, time, raw);
        };
  return kExitOk;
}

}  // namespace

int setUpRun(const Scene& scene, const RunOptions& options, std::ostream& log, RunSetup& setup) {
  setup.experiment = makeExperiment(scene);
  if (const int rc = makeWorld(scene, options, log, setup); rc != kExitOk) return rc;
  if (const std::string bad = countSteps(scene, setup.world->dt(), !options.restart.empty(), setup); !bad.empty()) {
    log << "error: " << (scene.source.empty() ? std::string("scene") : scene.source.string()) << ": " << bad << "\n";
    return kExitBadInput;
  }
  if (const int rc = prepareOutputFolder(options, log); rc != kExitOk) return rc;
  setup.modules = activeModules(scene, *setup.world, setup.experiment != nullptr);
  logSetup(scene, setup, options, log);
  if (const int rc = makeCameras(scene, options, log, setup); rc != kExitOk) return rc;
  // 64 KiB: a plain run's results.json takes 5, an experiment's a few tens.
  setup.results_file = std::make_unique<out::ReservedFile>(options.out_dir / "results.json", 64 * 1024);
  try {
    if (scene.run.hdf5)
      setup.run_file = std::make_unique<out::RunFile>(options.out_dir / "run.h5", scene.text);
    if (scene.run.vtk)
    {
      setup.vtk = std::make_unique<out::VtkSeries>(options.out_dir / "vtk", "particles");
      const auto& walls = scene.model.walls;
      if (std::any_of(walls.begin(), walls.end(), [](const sim::Wall& w) { return w.shape != sim::WallShape::Plane; }))
        setup.vtk_walls = std::make_unique<out::VtkSeries>(options.out_dir / "vtk", "walls");
    }
  } catch (const std::exception& e) {  // the folder was writable a moment ago: a full disk, a quota
    log << "error: cannot start the outputs in " << options.out_dir.string() << ": " << e.what() << "\n";
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace rocklab::experiments::detail
