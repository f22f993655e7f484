#pragma once
// Parameter sweeps and calibrations: a scene run once per value of one or more
// keys (the same --set mechanism as `rocklab run`), the chosen results.json
// figures collected into one table (sweep.csv) and a plot (sweep.png).
#include <filesystem>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

namespace rocklab::experiments {

struct SweepOptions {
  std::string scene;                    // file or built-in name
  std::vector<std::string> overrides;   // fixed --set assignments
  std::vector<std::pair<std::string, std::vector<std::string>>> vary;  // key -> TOML values
  std::vector<std::string> metrics;     // results.json paths ("wall_time_s.total"); empty = by experiment type
  // The plot's x: the first key's value divided by this results.json figure of each
  // run ("" = the value itself), e.g. a CSS over the clump's equivalent diameter.
  std::string x_over;
  std::filesystem::path out_dir;        // "" = out/<scene name>-sweep
  int threads = 0;                      // threads of an in-process run (0 = all cores)
  bool progress = true;
  // How the runs are carried out (run_plan.h): jobs < 0 = one process per core,
  // 0 = one after the other in this process (each with `threads`), N = N processes of
  // one thread each. plan_only: write the run list, Slurm script and README, run nothing.
  int jobs = -1;
  bool plan_only = false;
  struct Slurm {
    std::string time = "04:00:00";  // per run (array task)
    std::string memory = "4G";
    std::string partition;          // "" = the cluster's default
  } slurm;
};

/// Runs every combination of the varied values (the first key varies slowest).
/// Returns an ExitCode (2 on bad input before any run; 4 when some runs failed;
/// 130 when interrupted).
int runSweep(const SweepOptions& options, std::ostream& log);

/// `rocklab collect DIR`: merges the run folders of a sweep or study set (its
/// plan.json) into the same table, plot and recommendation as the command prints;
/// failed runs are listed with their exit code and error, missing ones as missing.
int collectSet(const std::filesystem::path& set_dir, std::ostream& log);

struct CalibrateOptions {
  SweepOptions sweep;       // exactly one varied key; values "a,b,c" or one range "lo:hi"
  std::string target_metric;
  double target = 0.0;
  int iterations = 8;       // bisection steps for a range
};

/// Finds the value of the varied key at which `target_metric` equals `target`:
/// a list is run in full and interpolated linearly between the bracketing
/// values; a range is bisected (the metric must change sides between lo and hi).
/// Prints the table it tried and the estimate.
int runCalibrate(const CalibrateOptions& options, std::ostream& log);

/// Splits "key=a,b,c" into the key and its values; throws std::invalid_argument.
std::pair<std::string, std::vector<std::string>> parseVary(const std::string& assignment);

}  // namespace rocklab::experiments
