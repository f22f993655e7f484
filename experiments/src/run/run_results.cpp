// Results of a run (run_internal.h): results.json, the cameras' and the
// experiment's reports, and the closing log lines.
#include <cstdlib>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "camera/wall_placement.h"
#include "common/json_text.h"
#include "report/build_info.h"
#include "report/run_report.h"
#include "run/run_internal.h"

namespace rocklab::experiments::detail {

namespace {

using json = nlohmann::json;

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

json clumpShapesJson(const std::vector<ClumpShapeReport>& shapes) {
  json list = json::array();
  for (const ClumpShapeReport& c : shapes)
    list.push_back({{"source", c.source},
                    {"shape", c.shape},
                    {"members", c.members},
                    {"mass_kg", c.mass},
                    {"volume_m3", c.volume},
                    {"equivalent_diameter_m", c.equivalent_diameter},
                    {"union_volume_m3", c.union_volume},
                    {"union_volume_error_m3", c.union_volume_error},
                    {"mass_distribution", c.distribution},
                    {"principal_inertia_kg_m2",
                     {c.principal_inertia.x(), c.principal_inertia.y(), c.principal_inertia.z()}}});
  return list;
}

json timestepJson(const RunSetup& setup, const RunRecord& record) {
  const sim::World& world = *setup.world;
  const auto& audit = world.timestepAudit();
  return {{"critical_s", audit.critical},
          {"spring_translational_s", audit.spring_translational},
          {"spring_rotational_s", audit.spring_rotational},
          {"rayleigh_s", audit.rayleigh},
          {"hertz_contact_time_s", audit.hertz_contact_time},
          {"linear_contact_time_s", audit.linear_contact_time},
          {"damped_limit_s", audit.damped_limit},
          {"automatic_s", audit.automatic},
          {"dt_over_critical", setup.dt / audit.critical},
          // Largest dt / stable step of the contact network seen by the watchdog
          // (it stops above 1), over every phase of an experiment.
          {"network_step_ratio_max", record.network_ratio},
          {"network_checks", record.network_checks}};
}

/// Wall time of each stage of World::step (sim/world.h), over every phase.
json stageSecondsJson(const RunRecord& record) {
  json stage_seconds = json::object();
  for (std::size_t k = 0; k < sim::kStageCount; ++k)
    stage_seconds[sim::stageName(static_cast<sim::Stage>(k))] = record.stage_seconds[k];
  return stage_seconds;
}

json lastObservedJson(const sim::Snapshot& last) {
  return {{"time_s", last.time},
          {"contacts", last.contacts},
          {"wall_contacts", last.wall_contacts},
          {"energy_J",
           {{"kinetic_translational", last.energy.kinetic_translational},
            {"kinetic_rotational", last.energy.kinetic_rotational},
            {"potential_gravity", last.energy.potential_gravity},
            {"elastic", last.energy.elastic}}}};
}

/// s of stepping: the loop (its last outputs included) less the time it spent
/// writing outputs; never below 0 (a clock's tick on a run of a few steps).
double steppingSeconds(const RunRecord& record) {
  return std::max(0.0, seconds(record.loop_start, record.loop_end) - record.output_seconds);
}

/// What the run did that makes its results doubtful without stopping it.
json warningsJson(const RunRecord& record) {
  json list = json::array();
  if (!record.far_travel.empty())
    list.push_back(record.far_travel + " (" + std::to_string(record.far_travel_steps) + " such steps in all)");
  return list;
}

/// What was run, for the report: the scene's file and description, its length, the source's commit.
json settingsJson(const Scene& scene) {
  json s = {{"source", scene.source.string()}, {"description", scene.run.description}};
  if (scene.run.steps > 0) s["steps"] = scene.run.steps;
  else s["end_time_s"] = scene.run.end_time;
  if (*sourceCommit() != '\0') s["commit"] = sourceCommit();
  return s;
}

/// The figures of the World and the run, before the cameras and the experiment add theirs.
json runJson(const Scene& scene, const RunSetup& setup, const RunRecord& record,
             const RunTimes& times) {
  const sim::World& world = *setup.world;
  const double stepping = steppingSeconds(record);
  json r;
  r["scene"] = scene.run.name;
  r["status"] = record.status;
  if (!record.message.empty()) r["message"] = record.message;
  r["warnings"] = warningsJson(record);
  r["particles"] = world.particles().size();  // at the end (an experiment may have removed bodies)
  r["clumps"] = world.particles().clumps.size();
  r["particles_at_start"] = record.start_balls;
  r["clumps_at_start"] = record.start_clumps;
  if (!scene.clump_shapes.empty()) r["clump_shapes"] = clumpShapesJson(scene.clump_shapes);
  r["walls"] = world.model().walls.size();
  r["wall_placement"] = wallPlacement(world.model());  // for `rocklab render` (camera/wall_placement.h)
  // The team the run stepped with: an experiment that removes bodies (a chute's
  // discharge) ends with fewer balls and its last World may need fewer threads.
  r["threads"] = record.start_team > 0 ? record.start_team : world.fullTeam();
  r["threads_at_end"] = world.fullTeam();
  // Steps the adaptive team ran on one thread because it timed faster (sim/src/team_tuner.h).
  r["team"] = {{"probes", world.stats().team_probes},
               {"switches", world.stats().team_switches},
               {"single_thread_steps", world.stats().single_thread_steps}};
  // How waiting OpenMP threads behave (app/main.cpp sets a short spin unless the user chose).
  const char* wait_policy = std::getenv("OMP_WAIT_POLICY");
  const char* spin_count = std::getenv("GOMP_SPINCOUNT");
  r["openmp_wait"] = wait_policy ? std::string("OMP_WAIT_POLICY=") + wait_policy
                     : spin_count ? std::string("GOMP_SPINCOUNT=") + spin_count
                                  : std::string("libgomp default");
  r["modules"] = setup.modules;
  r["seed"] = scene.run.seed;
  r["settings"] = settingsJson(scene);
  r["steps"] = world.stepCount();
  r["steps_this_run"] = world.stepCount() - record.first_step;
  r["dt_s"] = setup.dt;
  r["simulated_time_s"] = world.time();
  r["timestep"] = timestepJson(setup, record);
  const double total = seconds(times.start, Clock::now());
  r["wall_time_s"] = {{"setup", seconds(times.start, times.setup_done)},
                      {"stepping", stepping},
                      {"output", record.output_seconds},
                      {"total", total},
                      // A restart's own time is `total`; these count the runs it continues
                      // too (their checkpoints carry it; null from a checkpoint that did not).
                      {"earlier_runs", detail::finiteOrNull(setup.earlier_wall_s)},
                      {"all_runs", detail::finiteOrNull(setup.earlier_wall_s + total)}};
  r["stage_seconds"] = stageSecondsJson(record);
  r["particle_steps_per_s"] =  // balls, members included
      stepping > 0 ? static_cast<double>(record.ball_steps) / stepping : 0.0;
  r["neighbour_rebuilds"] = world.stats().neighbour_rebuilds;
  r["pairs_in_list"] = world.stats().pairs_in_list;
  r["neighbour_search_s"] = world.stats().neighbour_seconds;
  r["last_observed"] = lastObservedJson(record.last);
  r["state_hash"] = hex(world.stateHash());
  r["peak_rss_bytes"] = peakRssBytes();
  // What this run left: run.h5 only when it was finished (a failed write removes
  // it); checkpoint.h5 of the step it holds (an earlier one when the last failed).
  r["outputs"] = {{"run_h5", record.run_file_kept ? "run.h5" : ""},
                  {"frames", record.frames},
                  {"vtk_frames", record.vtk_frames},
                  {"checkpoint", record.checkpoint_step >= 0 ? "checkpoint.h5" : ""}};
  if (record.checkpoint_step >= 0) r["outputs"]["checkpoint_step"] = record.checkpoint_step;
  return r;
}

/// The cameras finish their movies; their list and the share of the wall time they took.
void reportCameras(RunSetup& setup, const RunTimes& times, json& r, std::ostream& log) {
  if (setup.cameras.empty()) return;
  json list = json::array();
  double render_s = 0;
  for (auto& c : setup.cameras) {
    c->finish(list);
    render_s += c->seconds();
  }
  r["cameras"] = list;
  r["render_share_of_wall_time"] = render_s / std::max(1e-9, seconds(times.start, Clock::now()));
  std::ostringstream line;  // its own stream: the precision must not leak into later lines
  line << "rocklab: cameras rendered in " << render_s << " s (" << std::fixed
       << std::setprecision(1) << 100.0 * r["render_share_of_wall_time"].get<double>()
       << " % of the wall time)\n";
  log << line.str();
}

void reportExperiment(const Scene& scene, const RunOptions& options, RunSetup& setup,
                      const RunRecord& record, json& r, std::ostream& log) {
  if (!setup.experiment) return;
  r["experiment"] = scene.experiment_type;
  if (record.status == "completed" && !record.experiment_over)
    r["experiment_status"] = "time limit (scene.end_time) reached first";
  setup.experiment->report(r, options.out_dir, log);
}

}  // namespace

int writeResults(const Scene& scene, const RunOptions& options, RunSetup& setup, RunRecord& record,
                 const RunTimes& times, std::ostream& log) {
  json r = runJson(scene, setup, record, times);
  try {
    reportCameras(setup, times, r, log);
    reportExperiment(scene, options, setup, record, r, log);
  } catch (const std::exception& e) {  // a movie, plot or table it could not write (a full disk)
    record.outputFailed(e.what());
    r["status"] = record.status;
    r["message"] = record.message;
  }
  try {
    setup.results_file->write(jsonText(r));
  } catch (const std::exception& e) {
    log << "error: " << e.what() << "\n";
    if (record.exit_code == kExitOk) record.exit_code = kExitFailed;
  }
  // The page is made from what results.json says and the files the run left; one that
  // cannot be written (a full disk) fails the run like any other output.
  try {
    writeRunReport(options.out_dir, r);
  } catch (const std::exception& e) {
    log << "error: report.html: " << e.what() << "\n";
    if (record.exit_code == kExitOk) record.exit_code = kExitFailed;
  }

  if (!record.message.empty()) log << "error: " << record.message << "\n";
  const sim::World& world = *setup.world;
  log << "rocklab: " << record.status << " at t = " << world.time() << " s after "
      << world.stepCount() - record.first_step << " steps; wall time " << std::fixed
      << std::setprecision(2) << seconds(times.start, Clock::now()) << " s (stepping "
      << steppingSeconds(record) << " s, " << std::scientific << std::setprecision(3)
      << r["particle_steps_per_s"].get<double>() << " particle-steps/s); results in "
      << (options.out_dir / "results.json").string() << ", report "
      << (options.out_dir / "report.html").string() << "\n";
  return record.exit_code;
}

}  // namespace rocklab::experiments::detail
