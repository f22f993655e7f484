#pragma once
// The three parts of runScene (run.cpp), private to the library: set-up
// (run_setup.cpp: everything that can fail on bad input, before any output),
// stepping (run_loop.cpp: the step loop, its observer, checkpoints, progress)
// and results (run_results.cpp: results.json, the reports, the last log line).
#include <array>
#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "camera/camera_recorder.h"
#include "drivers/experiment.h"
#include "rocklab/experiments/run.h"
#include "rocklab/sim/output/file_write.h"
#include "rocklab/sim/output/run_file.h"
#include "rocklab/sim/output/vtk_series.h"
#include "rocklab/sim/world.h"

namespace rocklab::experiments::detail {

using Clock = std::chrono::steady_clock;

inline double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// What the set-up made for the run.
struct RunSetup {
  std::unique_ptr<sim::World> world;
  std::unique_ptr<Experiment> experiment;  // null for a plain run
  std::vector<std::string> modules;        // what the scene constructs (log, results.json)
  std::vector<std::unique_ptr<CameraRecorder>> cameras;
  std::unique_ptr<sim::output::RunFile> run_file;  // null without output.hdf5
  std::unique_ptr<sim::output::VtkSeries> vtk;     // null without output.vtk
  std::unique_ptr<sim::output::VtkSeries> vtk_walls;  // the mesh and polygon walls beside it (null: none)
  // Space for results.json set aside at the start: a disk that fills up during
  // the run still takes the file that says the run failed.
  std::unique_ptr<sim::output::ReservedFile> results_file;
  double dt = 0.0;  // s, of the first World: the step counts below are made with it
  std::uint64_t total_steps = 0;
  // Steps between trajectory frames, energy rows and checkpoints (0 = none).
  std::uint64_t frame_every = 0, energy_every = 0, checkpoint_every = 0;
  // The run's clock (run.cpp sets it first) and the wall time of the runs a restart
  // continues (s; 0 for a new run, NaN when the checkpoint did not say): checkpoints
  // carry their sum on, results.json reports it.
  Clock::time_point started = Clock::now();
  double earlier_wall_s = 0.0;
};

/// checkpoint.h5's /experiment: CBOR of {experiment: the type that wrote it,
/// format: this, state: Experiment::saveState()} (run_loop.cpp writes it,
/// run_setup.cpp reads it).
inline constexpr int kExperimentStateFormat = 1;

/// Builds the World (new, or from options.restart), the experiment, the cameras
/// and the output writers, and logs the set-up. Returns kExitOk, or
/// kExitBadInput with the reason in `log` (then nothing was written), or
/// kExitFailed when an output file cannot be created (a full disk).
int setUpRun(const Scene& scene, const RunOptions& options, std::ostream& log, RunSetup& setup);

/// How the stepping ended and what it counted, for results.json.
struct RunRecord {
  std::string status = "completed";
  std::string message;  // why it stopped early ("" when completed or interrupted)
  int exit_code = kExitOk;
  /// An output failed after the stepping stopped (a full disk): a completed or
  /// interrupted run becomes failed; a run already stopped keeps its status and
  /// adds the reason.
  void outputFailed(const std::string& reason) {
    if (message.find(reason) != std::string::npos) return;  // the same output failing again
    if (status == "completed" || status == "interrupted") {
      status = "failed";
      exit_code = kExitFailed;
      message = reason;
    } else {
      message += (message.empty() ? "" : "; ") + reason;
    }
  }
  bool run_file_kept = false;           // run.h5 finished and in place
  std::int64_t checkpoint_step = -1;    // step of the last checkpoint written, -1 none
  bool experiment_over = false;  // the experiment ended the run
  sim::Snapshot last;            // time, step, energy and contacts of the last observed step
  std::size_t frames = 0;        // trajectory frames written
  std::size_t vtk_frames = 0;
  std::uint64_t first_step = 0;  // step count when this run started (restarts: > 0)
  std::size_t start_balls = 0, start_clumps = 0;  // bodies when this run started (experiments may remove some)
  int start_team = 0;  // the World's full team when this run started (fewer balls later may mean fewer)
  std::uint64_t ball_steps = 0;  // balls stepped, summed over steps (bodies may be removed)
  // Summed (or the largest) over every World of the run (an experiment builds several).
  double network_ratio = 0.0;
  std::uint64_t network_checks = 0;
  std::array<double, sim::kStageCount> stage_seconds{};
  // Steps in which a ball moved farther than its radius (dt forced above the
  // automatic step only: sim::WorldStats) and the first of them described.
  std::uint64_t far_travel_steps = 0;
  std::string far_travel;
  double output_seconds = 0.0;  // s spent writing outputs
  Clock::time_point loop_start, loop_end;
};

/// Steps to the end time, a stop request, the experiment's end or an error
/// (caught and recorded); then the last checkpoint (none after the watchdog
/// stopped the run) and run.h5 closed.
RunRecord stepRun(const Scene& scene, const RunOptions& options, std::ostream& log,
                  RunSetup& setup);

/// Wall-clock moments of the run, for results.json.
struct RunTimes {
  Clock::time_point start, setup_done;
};

/// results.json (with the cameras' and the experiment's reports, which also
/// write their own files) and the closing log lines. A report or results.json
/// that cannot be written (a full disk) fails the run; returns its exit code.
int writeResults(const Scene& scene, const RunOptions& options, RunSetup& setup, RunRecord& record,
                 const RunTimes& times, std::ostream& log);

}  // namespace rocklab::experiments::detail
