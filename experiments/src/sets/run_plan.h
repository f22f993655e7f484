#pragma once
// A multi-run command (sweep, study) as a set of independent runs: one
// `rocklab run SCENE --out DIR/runs/NAME --set ...` line per variant, each its own
// process and folder, so that this process, GNU parallel or a Slurm array can
// run them, and `rocklab collect` can merge what finished.
//
// A set folder holds: plan.json (what the set is, for collect), runs.txt (one
// shell line per run), slurm.sbatch, README.md (how to run it elsewhere),
// runs/NAME/ (each run's outputs), logs/NAME.log and logs/NAME.exit (its
// messages and exit code). A run is complete when runs/NAME/results.json (written
// last, by rename) says "completed"; a complete run is never run again.
#include <filesystem>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sets/run_set.h"

namespace rocklab::experiments::detail {

/// One run of a set.
struct PlannedRun {
  std::string name;                    // folder name, from the varied values (stable)
  std::vector<std::string> values;     // one per varied key
  std::vector<std::string> overrides;  // every --set of the run: fixed, varied, and the seed
  std::string invalid;                 // the scene error when this variant cannot run ("" = valid)
};

/// The runs of a set: names, overrides (the scene's seed added unless varied),
/// and each variant validated (an invalid one is kept, with its message).
std::vector<PlannedRun> planRuns(const SweepOptions& o);

/// The shell line that runs one planned run from anywhere (absolute paths).
std::string runCommand(const std::filesystem::path& set_dir, const std::string& scene_path, const PlannedRun& run);

/// Writes plan.json (with `what`: the command's own settings), runs.txt,
/// slurm.sbatch and README.md into set_dir. An invalid run is in plan.json (with its
/// message) but not in runs.txt or the Slurm array: its log gets the message and its
/// exit code is 2, as when the set is run here.
void writePlanFiles(const std::filesystem::path& set_dir, const SweepOptions& o, const std::vector<PlannedRun>& runs,
                    const nlohmann::json& what);

/// After --plan: names the run list and each run left out as invalid. Returns
/// kExitBadInput when a run was left out, else kExitOk.
int reportPlan(const std::filesystem::path& set_dir, const std::vector<PlannedRun>& runs, const std::string& kind,
               std::ostream& log);

/// Runs every run that is not complete: in this process one after the other with
/// o.threads threads (o.jobs == 0), or as o.jobs processes of one thread each,
/// with one progress line for the set. Invalid runs are not started: their log
/// gets the message and their exit code is 2. Returns kExitInterrupted after
/// Ctrl-C, else kExitOk (failures are in the runs' exit codes).
int executeRuns(const std::filesystem::path& set_dir, const SweepOptions& o, const std::vector<PlannedRun>& runs,
                std::ostream& log);

/// What each run left: results.json when complete (code 0, status "ok"); else its
/// exit code and status "exit N: <the last error line of its log>"; code kMissing and
/// status "missing" when it never ran.
constexpr int kMissing = -1;
std::vector<Variant> inspectRuns(const std::filesystem::path& set_dir, const std::vector<PlannedRun>& runs);

/// The number of processes for --jobs when not given: the cores.
int defaultJobs();

/// `s` as one word for POSIX sh: bare when that means the same, else in single quotes.
std::string shellQuote(const std::string& s);

}  // namespace rocklab::experiments::detail
