#include "rocklab/experiments/run.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <unordered_set>

#include "common/atomic_file.h"
#include "camera/camera_recorder.h"
#include "drivers/experiment.h"
#include "rocklab/sim/output/checkpoint.h"
#include "rocklab/sim/output/run_file.h"
#include "rocklab/sim/output/vtk_series.h"
#include "rocklab/sim/world.h"

namespace rocklab::experiments {

namespace {

std::atomic<bool> g_stop{false};
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

std::string hex(std::uint64_t v) {
  std::ostringstream s;
  s << std::hex << std::setw(16) << std::setfill('0') << v;
  return s.str();
}

std::size_t peakRssBytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::size_t>(u.ru_maxrss) * 1024;
}

std::string clockText(double s) {
  std::ostringstream o;
  const auto total = static_cast<long>(std::lround(s));
  o << total / 3600 << ':' << std::setw(2) << std::setfill('0') << (total / 60) % 60 << ':' << std::setw(2)
    << total % 60;
  return o.str();
}

/// Progress on stderr: a line every 2 s on a terminal (overwritten), every 15 s otherwise.
class Progress {
 public:
  Progress(bool enabled, std::uint64_t total_steps, double dt)
      : enabled_(enabled), tty_(isatty(STDERR_FILENO)), total_(total_steps), dt_(dt),
        start_(Clock::now()), last_(start_) {}
  void update(std::uint64_t done, const std::string& extra) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (seconds(last_, now) < (tty_ ? 2.0 : 15.0)) return;
    last_ = now;
    const double elapsed = seconds(start_, now);
    const double rate = done / std::max(elapsed, 1e-9);
    const double eta = (total_ - done) / std::max(rate, 1e-9);
    std::ostringstream s;
    s << std::fixed << std::setprecision(4) << "t = " << done * dt_ << " / " << total_ * dt_ << " s  "
      << std::setprecision(1) << 100.0 * done / total_ << "%  " << std::setprecision(0) << rate
      << " steps/s  ETA " << clockText(eta) << "  " << extra;
    std::cerr << (tty_ ? "\r" : "") << s.str() << (tty_ ? "\033[K" : "\n") << std::flush;
    printed_ = true;
  }
  void finish() {
    if (enabled_ && tty_ && printed_) std::cerr << "\n";
  }

 private:
  bool enabled_, tty_;
  std::uint64_t total_;
  double dt_;
  Clock::time_point start_, last_;
  bool printed_ = false;
};

/// Active modules: what this scene constructs (and so pays for), for the log and results.json.
std::vector<std::string> activeModules(const Scene& scene, const sim::World& world, bool has_experiment) {
  const sim::Model& model = world.model();
  std::vector<std::string> modules;
  modules.push_back(model.contact.law == sim::ContactLaw::Linear ? "contact:linear" : "contact:hertz_mindlin");
  if (model.contact.damping_normal > 0 || model.contact.damping_shear > 0) modules.push_back("damping:viscous");
  if (model.contact.local_damping > 0) modules.push_back("damping:local");
  const std::pair<sim::WallShape, const char*> shapes[] = {
      {sim::WallShape::Plane, "walls:plane"}, {sim::WallShape::Polygon, "walls:polygon"}, {sim::WallShape::Mesh, "walls:mesh"}};
  auto anyWall = [&model](auto predicate) { return std::any_of(model.walls.begin(), model.walls.end(), predicate); };
  for (const auto& [shape, name] : shapes)
    if (anyWall([shape = shape](const sim::Wall& w) { return w.shape == shape; })) modules.push_back(name);
  if (anyWall([](const sim::Wall& w) { return !w.motion.isStatic(); })) modules.push_back("walls:moving");
  if (!model.gravity_changes.empty()) modules.push_back("gravity:schedule");
  if (world.particles().clumps.size() > 0) modules.push_back("clumps");
  if (has_experiment) modules.push_back("experiment:" + scene.experiment_type);
  if (!scene.cameras.empty()) modules.push_back("render:" + std::to_string(scene.cameras.size()) + " camera(s)");
  if (scene.run.hdf5) modules.push_back("output:hdf5");
  if (scene.run.vtk) modules.push_back("output:vtk");
  if (scene.run.checkpoint) modules.push_back("output:checkpoint");
  return modules;
}

/// The set-up lines of the log: scene, modules, clump shapes, time-step audit, steps.
void logSetup(const Scene& scene, const sim::World& world, const RunOptions& options,
              const std::vector<std::string>& modules, std::uint64_t total_steps, std::ostream& log) {
  const sim::Model& model = world.model();
  log << "rocklab: scene '" << scene.run.name << "'" << (options.restart.empty() ? "" : " (restart)") << ", "
      << world.particles().size() << " balls (" << world.particles().clumps.size() << " clumps), "
      << model.walls.size() << " walls, threads: "
      << world.threads() << "\n";
  log << "  modules: ";
  for (std::size_t k = 0; k < modules.size(); ++k) log << (k ? ", " : "") << modules[k];
  log << "\n";
  for (const ClumpShapeReport& c : scene.clump_shapes)
    log << "  clump shape of " << c.source << ": " << c.shape << ", " << c.members << " members, mass "
        << c.mass * 1e3 << " g (" << c.distribution << " distribution), volume " << c.volume * 1e9
        << " mm^3 (equivalent diameter " << c.equivalent_diameter * 1e3 << " mm); true union volume "
        << c.union_volume * 1e9 << " +- " << c.union_volume_error * 1e9 << " mm^3\n";
  log << world.timestepAudit().describe(model.timestep) << "\n";
  log << "  steps: " << total_steps << " from t = " << world.time() << " s, output to " << options.out_dir.string()
      << "\n";
}

}  // namespace

void requestStop() { g_stop = true; }
bool stopRequested() { return g_stop; }

int runScene(const Scene& scene, const RunOptions& options, std::ostream& log) {
  const auto t_start = Clock::now();
  g_stop = false;
  namespace fs = std::filesystem;
  namespace out = sim::output;

  // --- set-up: everything that can fail on bad input happens before any output.
  std::unique_ptr<sim::World> world;
  std::string scene_text = scene.text;
  try {
    if (!options.restart.empty()) {
      out::Checkpoint cp = out::readCheckpoint(options.restart);
      world = std::make_unique<sim::World>(scene.model, std::move(cp.state), options.threads);
    } else {
      world = std::make_unique<sim::World>(scene.model, scene.spheres, scene.clumps, options.threads);
    }
  } catch (const out::CheckpointError& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    log << "error: " << (scene.source.empty() ? std::string("scene") : scene.source.string()) << ": "
        << e.what() << "\n";
    return kExitBadInput;
  }
  std::unique_ptr<Experiment> experiment = makeExperiment(scene);
  if (experiment && !options.restart.empty()) {
    log << "error: " << scene.source.string() << ": experiment." << scene.experiment_type
        << " scenes cannot be restarted from a checkpoint yet (the experiment's phase is not saved); run the scene again\n";
    return kExitBadInput;
  }
  const double dt = world->dt();
  const std::uint64_t total_steps =
      scene.run.steps > 0 ? scene.run.steps
                          : static_cast<std::uint64_t>(std::llround(scene.run.end_time / dt));
  auto stepsFor = [dt](double interval) -> std::uint64_t {
    return interval > 0 ? std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(interval / dt))) : 0;
  };
  const std::uint64_t frame_every = stepsFor(scene.run.frame_interval);
  const std::uint64_t energy_every = stepsFor(scene.run.energy_interval);
  const std::uint64_t checkpoint_every = stepsFor(scene.run.checkpoint_interval);

  std::error_code ec;
  fs::create_directories(options.out_dir, ec);
  if (ec) {
    log << "error: cannot create output directory " << options.out_dir << ": " << ec.message() << "\n";
    return kExitBadInput;
  }

  const sim::Model& model = world->model();
  const std::vector<std::string> modules = activeModules(scene, *world, experiment != nullptr);
  logSetup(scene, *world, options, modules, total_steps, log);

  // Cameras: the GL context is made here, only when the scene has a camera.
  std::vector<std::unique_ptr<CameraRecorder>> cameras;
  try {
    for (const CameraSettings& c : scene.cameras)
      cameras.push_back(std::make_unique<CameraRecorder>(c, scene, options.out_dir, log));
  } catch (const std::exception& e) {
    log << "error: camera: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (experiment && !experiment->trackingCamera().empty())
    for (auto& c : cameras)
      if (c->settings().name == experiment->trackingCamera())
        c->on_frame = [&experiment](std::uint64_t frame, double time, const cv::Mat& raw) {
          experiment->cameraFrame(frame, time, raw);
        };
  std::unique_ptr<out::RunFile> run_file;
  std::unique_ptr<out::VtkSeries> vtk;
  if (scene.run.hdf5) run_file = std::make_unique<out::RunFile>(options.out_dir / "run.h5", scene_text);
  if (scene.run.vtk) vtk = std::make_unique<out::VtkSeries>(options.out_dir / "vtk", "particles");
  const auto t_setup = Clock::now();

  // --- stepping
  double output_seconds = 0.0;
  std::string status = "completed", message;
  int exit_code = kExitOk;
  sim::Snapshot last;  // figures of the last observed step
  std::size_t frames = 0;
  bool frame_due = false;  // set by the loop before an observed step
  bool experiment_due = false, energy_due = false, camera_due = false;
  auto observer = [&](const sim::Snapshot& s) {
    if (experiment_due) experiment->observe(s);
    if (camera_due) {
      const auto markers = experiment ? experiment->markerBodies() : std::unordered_set<std::uint64_t>{};
      for (auto& c : cameras)
        if (c->due(s.time)) c->record(s, world->model(), markers);
    }
    if (!frame_due && !energy_due) return;
    const auto t0 = Clock::now();
    last.time = s.time;
    last.step = s.step;
    last.energy = s.energy;
    last.contacts = s.contacts;
    last.wall_contacts = s.wall_contacts;
    if (run_file) {
      run_file->appendEnergy(s);
      if (frame_due) run_file->writeFrame(s);
    }
    if (vtk && frame_due) vtk->writeFrame(s);
    if (frame_due) ++frames;
    output_seconds += seconds(t0, Clock::now());
  };
  auto writeCheckpoint = [&]() {
    if (!scene.run.checkpoint) return;
    const auto t0 = Clock::now();
    out::writeCheckpoint(options.out_dir / "checkpoint.h5", world->exportState(), scene_text);
    output_seconds += seconds(t0, Clock::now());
  };

  Progress progress(options.progress, total_steps, dt);
  const std::uint64_t first_step = world->stepCount();
  const std::uint64_t end_step = std::max(total_steps, first_step);
  const auto t_loop = Clock::now();
  const ExperimentContext context{options.threads, &log};
  bool experiment_over = false;
  std::uint64_t ball_steps = 0;  // balls stepped, summed over steps (bodies may be removed)
  double network_ratio = 0.0;    // largest network step ratio over every World of the run
  // Network checks and seconds per engine stage, summed over the Worlds an
  // experiment builds: a World's counters start at 0, and switchPhase makes the
  // new World before the old one goes, so a new address is a new World.
  std::uint64_t checks_before = 0, checks_seen = 0;
  std::array<double, sim::kStageCount> stages_before{}, stages_seen{};
  const sim::World* world_seen = nullptr;
  try {
    while (world->stepCount() < end_step) {
      if (g_stop) {
        status = "interrupted";
        exit_code = kExitInterrupted;
        break;
      }
      if (experiment && !experiment_over) experiment_over = !experiment->advance(world, context);
      // Frames at t = 0, every frame interval and at the last step (or the step
      // the experiment ended); energy rows at frames and every energy interval.
      const std::uint64_t k = world->stepCount();
      frame_due = k == first_step || k + 1 >= end_step || experiment_over || (frame_every && k % frame_every == 0);
      experiment_due = experiment && !experiment_over && experiment->wantsSnapshot(k);
      energy_due = energy_every && k % energy_every == 0;
      camera_due = std::any_of(cameras.begin(), cameras.end(), [&](const auto& c) { return c->due(world->time()); });
      ball_steps += world->particles().size();
      if (frame_due || experiment_due || energy_due || camera_due)
        world->step(observer);
      else
        world->step();
      if (world.get() != world_seen) {  // a new World (phase)
        checks_before += checks_seen;
        for (std::size_t s = 0; s < sim::kStageCount; ++s) stages_before[s] += stages_seen[s];
        world_seen = world.get();
      }
      checks_seen = world->stats().network_checks;
      stages_seen = world->stats().stage_seconds;
      network_ratio = std::max(network_ratio, world->stats().network_step_ratio);
      if (checkpoint_every && world->stepCount() % checkpoint_every == 0) writeCheckpoint();
      progress.update(world->stepCount(), experiment ? experiment->progress() : "");
      if (experiment_over) break;
    }
  } catch (const sim::WatchdogError& e) {
    status = "stopped_by_watchdog";
    message = e.what();
    exit_code = kExitWatchdog;
  } catch (const std::invalid_argument& e) {
    // A phase switch of the experiment made an unusable world (e.g. a wall
    // setting that only fails once the wall is placed): stop, keep the outputs.
    status = "failed";
    message = std::string("experiment phase switch: ") + e.what();
    exit_code = kExitBadInput;
  } catch (const std::exception& e) {
    // Anything else the experiment or an output met (a photograph it cannot read, a
    // full disk): stop with the reason instead of aborting; outputs so far are kept.
    status = "failed";
    message = e.what();
    exit_code = kExitFailed;
  }
  const auto t_loop_end = Clock::now();
  progress.finish();
  if (exit_code != kExitWatchdog) writeCheckpoint();  // a blown-up state is no place to restart from
  const auto t_out = Clock::now();
  if (run_file) run_file->close(exit_code != kExitOk);
  const std::size_t vtk_frames = vtk ? vtk->frameCount() : 0;
  output_seconds += seconds(t_out, Clock::now());

  const double stepping = seconds(t_loop, t_loop_end) - output_seconds;
  const std::uint64_t steps_done = world->stepCount() - first_step;
  const auto& audit = world->timestepAudit();
  nlohmann::json r;
  r["scene"] = scene.run.name;
  r["status"] = status;
  if (!message.empty()) r["message"] = message;
  r["particles"] = world->particles().size();
  r["clumps"] = world->particles().clumps.size();
  if (!scene.clump_shapes.empty()) {
    nlohmann::json list = nlohmann::json::array();
    for (const ClumpShapeReport& c : scene.clump_shapes)
      list.push_back({{"source", c.source},
                        {"shape", c.shape},
                        {"members", c.members},
                        {"mass_kg", c.mass},
                        {"volume_m3", c.volume},
                        {"equivalent_diameter_m", c.equivalent_diameter},
                        {"union_volume_m3", c.union_volume},
                        {"union_volume_error_m3", c.union_volume_error},
                        {"mass_distribution", c.distribution},
                        {"principal_inertia_kg_m2", {c.principal_inertia.x(), c.principal_inertia.y(), c.principal_inertia.z()}}});
    r["clump_shapes"] = list;
  }
  r["walls"] = model.walls.size();
  r["threads"] = world->threads();
  r["modules"] = modules;
  r["seed"] = scene.run.seed;
  r["steps"] = world->stepCount();
  r["steps_this_run"] = steps_done;
  r["dt_s"] = dt;
  r["simulated_time_s"] = world->time();
  r["timestep"] = {{"critical_s", audit.critical},
                   {"spring_translational_s", audit.spring_translational},
                   {"spring_rotational_s", audit.spring_rotational},
                   {"rayleigh_s", audit.rayleigh},
                   {"hertz_contact_time_s", audit.hertz_contact_time},
                   {"linear_contact_time_s", audit.linear_contact_time},
                   {"damped_limit_s", audit.damped_limit},
                   {"automatic_s", audit.automatic},
                   {"dt_over_critical", dt / audit.critical},
                   // Largest dt / stable step of the contact network seen by the watchdog
                   // (it stops above 1), over every phase of an experiment.
                   {"network_step_ratio_max", network_ratio},
                   {"network_checks", checks_before + checks_seen}};
  r["wall_time_s"] = {{"setup", seconds(t_start, t_setup)},
                      {"stepping", stepping},
                      {"output", output_seconds},
                      {"total", seconds(t_start, Clock::now())}};
  // Wall time of each stage of World::step (sim/world.h), over every phase.
  nlohmann::json stage_seconds = nlohmann::json::object();
  for (std::size_t k = 0; k < sim::kStageCount; ++k)
    stage_seconds[sim::stageName(static_cast<sim::Stage>(k))] = stages_before[k] + stages_seen[k];
  r["stage_seconds"] = stage_seconds;
  r["particle_steps_per_s"] = stepping > 0 ? static_cast<double>(ball_steps) / stepping : 0.0;  // balls, members included
  r["neighbour_rebuilds"] = world->stats().neighbour_rebuilds;
  r["pairs_in_list"] = world->stats().pairs_in_list;
  r["neighbour_search_s"] = world->stats().neighbour_seconds;
  r["last_observed"] = {{"time_s", last.time},
                        {"contacts", last.contacts},
                        {"wall_contacts", last.wall_contacts},
                        {"energy_J",
                         {{"kinetic_translational", last.energy.kinetic_translational},
                          {"kinetic_rotational", last.energy.kinetic_rotational},
                          {"potential_gravity", last.energy.potential_gravity},
                          {"elastic", last.energy.elastic}}}};
  r["state_hash"] = hex(world->stateHash());
  r["peak_rss_bytes"] = peakRssBytes();
  r["outputs"] = {{"run_h5", scene.run.hdf5 ? "run.h5" : ""},
                  {"frames", frames},
                  {"vtk_frames", vtk_frames},
                  {"checkpoint", scene.run.checkpoint && exit_code != kExitWatchdog ? "checkpoint.h5" : ""}};
  if (!cameras.empty()) {
    nlohmann::json list = nlohmann::json::array();
    double render_s = 0;
    for (auto& c : cameras) {
      c->finish(list);
      render_s += c->seconds();
    }
    r["cameras"] = list;
    r["render_share_of_wall_time"] = render_s / std::max(1e-9, seconds(t_start, Clock::now()));
    std::ostringstream line;  // its own stream: the precision must not leak into later lines
    line << "rocklab: cameras rendered in " << render_s << " s (" << std::fixed << std::setprecision(1)
         << 100.0 * r["render_share_of_wall_time"].get<double>() << " % of the wall time)\n";
    log << line.str();
  }
  if (experiment) {
    r["experiment"] = scene.experiment_type;
    if (status == "completed" && !experiment_over) r["experiment_status"] = "time limit (scene.end_time) reached first";
    experiment->report(r, options.out_dir, log);
  }
  detail::writeAtomically(options.out_dir / "results.json", r.dump(2) + "\n");

  if (!message.empty()) log << "error: " << message << "\n";
  log << "rocklab: " << status << " at t = " << world->time() << " s after " << steps_done << " steps; wall time "
      << std::fixed << std::setprecision(2) << seconds(t_start, Clock::now()) << " s (stepping " << stepping
      << " s, " << std::scientific << std::setprecision(3) << r["particle_steps_per_s"].get<double>()
      << " particle-steps/s); results in " << (options.out_dir / "results.json").string() << "\n";
  return exit_code;
}

}  // namespace rocklab::experiments
