// Stepping of a run (run_internal.h): the experiment advanced before every
// step, the observer only on steps something looks at (frames, energy rows,
// the experiment, cameras), checkpoints, progress on stderr.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <unordered_set>

#include "rocklab/sim/output/checkpoint.h"
#include "run/run_internal.h"

namespace rocklab::experiments::detail {

namespace {

std::string clockText(double s) {
  std::ostringstream o;
  const auto total = static_cast<long>(std::lround(s));
  o << total / 3600 << ':' << std::setw(2) << std::setfill('0') << (total / 60) % 60 << ':'
    << std::setw(2) << total % 60;
  return o.str();
}

/// Progress on stderr: a line every 2 s on a terminal (overwritten), every 15 s otherwise.
class Progress {
 public:
  /// `first_step`: the step count the run starts from (a restart's is its checkpoint's),
  /// so that steps/s and the ETA count only what this process stepped. `may_end_early`:
  /// an experiment that can end on its own criterion (a chute's clearance, a deposit that
  /// settles) before scene.end_time, whose ETA is then an upper bound ("ETA <=").
  Progress(bool enabled, std::uint64_t total_steps, std::uint64_t first_step, double dt, bool may_end_early)
      : enabled_(enabled),
        may_end_early_(may_end_early),
        tty_(isatty(STDERR_FILENO)),
        total_(total_steps),
        first_(first_step),
        dt_(dt),
        start_(Clock::now()),
        last_(start_) {}
  /// `extra()` gives the experiment's part of the line; called only when a line
  /// is printed (building it every step cost a tenth of a small run's time).
  template <class Extra>
  void update(std::uint64_t done, Extra&& extra) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (seconds(last_, now) < (tty_ ? 2.0 : 15.0)) return;
    last_ = now;
    const double elapsed = seconds(start_, now);
    const double rate = static_cast<double>(done - std::min(done, first_)) / std::max(elapsed, 1e-9);
    const double eta = (total_ - done) / std::max(rate, 1e-9);
    std::ostringstream s;
    s << std::fixed << std::setprecision(4) << "t = " << done * dt_ << " / " << total_ * dt_
      << " s  " << std::setprecision(1) << 100.0 * done / total_ << "%  " << std::setprecision(0)
      << rate << " steps/s  ETA " << (may_end_early_ ? "<= " : "") << clockText(eta) << "  " << extra();
    std::cerr << (tty_ ? "\r" : "") << s.str() << (tty_ ? "\033[K" : "\n") << std::flush;
    printed_ = true;
  }
  void finish() {
    if (enabled_ && tty_ && printed_) std::cerr << "\n";
  }

 private:
  bool enabled_, may_end_early_, tty_;
  std::uint64_t total_, first_;
  double dt_;
  Clock::time_point start_, last_;
  bool printed_ = false;
};

/// Network checks and seconds per engine stage, summed over the Worlds an
/// experiment builds: a World's counters start at 0, and switchPhase makes the
/// new World before the old one goes, so a new address is a new World.
class WorldStatsSum {
 public:
  /// Returns true when the World warned for the first time in the run (record.far_travel).
  bool after(const sim::World& world, RunRecord& record) {
    if (&world != seen_) {  // a new World (phase)
      checks_before_ += checks_seen_;
      far_before_ += far_seen_;
      for (std::size_t s = 0; s < sim::kStageCount; ++s) stages_before_[s] += stages_seen_[s];
      seen_ = &world;
    }
    const sim::WorldStats& stats = world.stats();
    checks_seen_ = stats.network_checks;
    far_seen_ = stats.far_travel_steps;
    stages_seen_ = stats.stage_seconds;
    record.network_ratio = std::max(record.network_ratio, stats.network_step_ratio);
    record.network_checks = checks_before_ + checks_seen_;
    record.far_travel_steps = far_before_ + far_seen_;
    for (std::size_t s = 0; s < sim::kStageCount; ++s)
      record.stage_seconds[s] = stages_before_[s] + stages_seen_[s];
    if (!record.far_travel.empty() || stats.far_travel.empty()) return false;
    record.far_travel = stats.far_travel;
    return true;
  }

 private:
  std::uint64_t checks_before_ = 0, checks_seen_ = 0, far_before_ = 0, far_seen_ = 0;
  std::array<double, sim::kStageCount> stages_before_{}, stages_seen_{};
  const sim::World* seen_ = nullptr;
};

class RunLoop {
 public:
  RunLoop(const Scene& scene, const RunOptions& options, std::ostream& log, RunSetup& setup)
      : scene_(scene),
        options_(options),
        setup_(setup),
        world_(setup.world),
        context_{options.threads, &log},
        progress_(options.progress, setup.total_steps, setup.world->stepCount(), setup.dt, setup.experiment != nullptr) {}

  RunRecord run() {
    record_.first_step = world_->stepCount();
    record_.start_balls = world_->particles().size();
    record_.start_clumps = world_->particles().clumps.size();
    record_.start_team = world_->fullTeam();
    end_step_ = std::max(setup_.total_steps, record_.first_step);
    record_.loop_start = Clock::now();
    try {
      while (world_->stepCount() < end_step_ && stepOnce()) {
      }
    } catch (const sim::WatchdogError& e) {
      stopWith("stopped_by_watchdog", e.what(), kExitWatchdog);
    } catch (const std::invalid_argument& e) {
      // The experiment found its settings unusable once running (a wall setting that
      // only fails once the wall is placed, a step too long for the crusher's smallest
      // fragment): bad input, named by the message; stop, keep the outputs.
      stopWith("failed", "experiment \"" + scene_.experiment_type + "\": " + e.what(), kExitBadInput);
    } catch (const std::exception& e) {
      // Anything else the experiment or an output met (a photograph it cannot read, a
      // full disk): stop with the reason instead of aborting; outputs so far are kept.
      stopWith("failed", e.what(), kExitFailed);
    }
    progress_.finish();
    finishOutputs();
    // After the last outputs: their time is in output_seconds, so it must be in the loop too.
    record_.loop_end = Clock::now();
    return record_;
  }

 private:
  /// One step with what comes before and after it; false = the run stops here.
  bool stepOnce() {
    if (stopRequested()) {
      stopWith("interrupted", "", kExitInterrupted);
      return false;
    }
    Experiment* experiment = setup_.experiment.get();
    if (experiment && !record_.experiment_over) {
      record_.experiment_over = !experiment->advance(world_, context_);
      if (experiment->advanceUndone()) {  // the checkpoint is the state before this step's advance
        stopWith("interrupted", "", kExitInterrupted);
        return false;
      }
      if (record_.experiment_over && experiment->endsBeforeStep()) return false;
    }
    chooseObservations();
    record_.ball_steps += world_->particles().size();
    if (frame_due_ || experiment_due_ || energy_due_ || camera_due_)
      world_->step([this](const sim::Snapshot& s) { observe(s); });
    else
      world_->step();
    if (stats_.after(*world_, record_)) *context_.log << "warning: " << record_.far_travel << "\n";
    const std::uint64_t done = world_->stepCount();
    if (setup_.checkpoint_every && done % setup_.checkpoint_every == 0) writeCheckpoint();
    progress_.update(done, [experiment] { return experiment ? experiment->progress() : std::string(); });
    return !record_.experiment_over;
  }

  /// What the coming step shows to whom. Frames at t = 0, every frame interval
  /// and at the last step (or the step the experiment ended); energy rows at
  /// frames and every energy interval.
  void chooseObservations() {
    const std::uint64_t k = world_->stepCount();
    const Experiment* experiment = setup_.experiment.get();
    frame_due_ = k == record_.first_step || k + 1 >= end_step_ || record_.experiment_over ||
                 (setup_.frame_every && k % setup_.frame_every == 0);
    experiment_due_ = experiment && !record_.experiment_over && experiment->wantsSnapshot(k);
    energy_due_ = setup_.energy_every && k % setup_.energy_every == 0;
    camera_due_ = std::any_of(setup_.cameras.begin(), setup_.cameras.end(),
                              [&](const auto& c) { return c->due(world_->time()); });
  }

  void observe(const sim::Snapshot& s) {
    if (experiment_due_) setup_.experiment->observe(s);
    if (camera_due_) {
      const auto markers = setup_.experiment ? setup_.experiment->markerBodies()
                                             : std::unordered_set<std::uint64_t>{};
      for (auto& c : setup_.cameras)
        if (c->due(s.time)) c->record(s, world_->model(), markers);
    }
    if (frame_due_ || energy_due_) writeObservation(s);
  }

  /// The energy row, the frame when one is due, and the last observed figures.
  void writeObservation(const sim::Snapshot& s) {
    const auto t0 = Clock::now();
    sim::Snapshot& last = record_.last;
    last.time = s.time;
    last.step = s.step;
    last.energy = s.energy;
    last.contacts = s.contacts;
    last.wall_contacts = s.wall_contacts;
    if (setup_.run_file) {
      setup_.run_file->appendEnergy(s);
      // With the materials the experiment made (a breakage's fragment classes):
      // `rocklab render` needs them to draw the frame.
      if (frame_due_) setup_.run_file->writeFrame(s, world_->model().materials);
    }
    if (setup_.vtk && frame_due_) setup_.vtk->writeFrame(s);
    if (setup_.vtk_walls && frame_due_) setup_.vtk_walls->writeWalls(world_->model(), s.time);
    if (frame_due_) ++record_.frames;
    record_.output_seconds += seconds(t0, Clock::now());
  }

  void writeCheckpoint() {
    if (!scene_.run.checkpoint) return;
    const auto t0 = Clock::now();
    // A restartable experiment's own state beside the World (run_setup.cpp reads it).
    std::vector<std::uint8_t> experiment_state;
    if (const Experiment* experiment = setup_.experiment.get(); experiment && experiment->restartable())
      experiment_state = nlohmann::json::to_cbor(
          {{"experiment", scene_.experiment_type}, {"format", kExperimentStateFormat}, {"state", experiment->saveState()}});
    sim::output::writeCheckpoint(options_.out_dir / "checkpoint.h5", world_->exportState(), scene_.text,
                                 experiment_state, setup_.earlier_wall_s + seconds(setup_.started, Clock::now()));
    record_.checkpoint_step = static_cast<std::int64_t>(world_->stepCount());
    record_.output_seconds += seconds(t0, Clock::now());
  }

  /// The last checkpoint (a blown-up state is no place to restart from) and run.h5
  /// closed, each on its own: an output that fails (a full disk) fails the run
  /// with its reason, and the others are still tried. A run.h5 a write failed in
  /// is removed first (it cannot be finished; its space may let the checkpoint fit).
  void finishOutputs() {
    const auto t0 = Clock::now();
    sim::output::RunFile* run_file = setup_.run_file.get();
    const bool run_file_failed = run_file && run_file->failed();
    if (run_file_failed) {
      run_file->discard();
      const std::string partial = (options_.out_dir / "run.h5.partial").string();
      if (record_.message.find(partial) == std::string::npos)
        record_.outputFailed("run file '" + partial + "': a write to it failed; removed");
    }
    if (record_.exit_code != kExitWatchdog) guardOutput([&] { writeCheckpoint(); });
    if (run_file && !run_file_failed)
      guardOutput([&] {
        run_file->close(record_.exit_code != kExitOk);
        record_.run_file_kept = true;
      });
    record_.vtk_frames = setup_.vtk ? setup_.vtk->frameCount() : 0;
    record_.output_seconds += seconds(t0, Clock::now());
  }

  template <class Output>
  void guardOutput(Output&& output) {
    try {
      output();
    } catch (const std::exception& e) {
      record_.outputFailed(e.what());
    }
  }

  void stopWith(const std::string& status, const std::string& message, int exit_code) {
    record_.status = status;
    record_.message = message;
    record_.exit_code = exit_code;
  }

  const Scene& scene_;
  const RunOptions& options_;
  RunSetup& setup_;
  std::unique_ptr<sim::World>& world_;  // the experiment may replace it
  const ExperimentContext context_;
  Progress progress_;
  WorldStatsSum stats_;
  RunRecord record_;
  std::uint64_t end_step_ = 0;
  bool frame_due_ = false, experiment_due_ = false, energy_due_ = false, camera_due_ = false;
};

}  // namespace

RunRecord stepRun(const Scene& scene, const RunOptions& options, std::ostream& log,
                  RunSetup& setup) {
  return RunLoop(scene, options, log, setup).run();
}

}  // namespace rocklab::experiments::detail
