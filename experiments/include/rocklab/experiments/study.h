#pragma once
// Error against run time: a scene run for every combination of --vary values, one
// figure of results.json compared with a reference (the finest variant, or a lab
// value), tabulated against the wall time, with the Pareto front (no other variant
// is both cheaper and closer) and the cheapest variant within a stated error. This
// is how a user picks settings (time step, stiffness, resolution, frame rate...).
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "rocklab/experiments/sweep.h"

namespace rocklab::experiments {

struct StudyOptions {
  SweepOptions runs;                // scene, --set, --vary (list from cheapest to finest), --out, threads
  std::string figure;               // results.json dotted path of the figure studied
  std::optional<double> reference;  // a lab value; none = the finest variant (the last one listed);
                                    // 0 for a figure that is an error already (tracking.rms_error_pct):
                                    // then the error is the figure itself, in its unit
  double tolerance_pct = 5.0;       // the recommendation: cheapest variant from which on every
                                    // variant listed after it is within this error
  std::string description;          // from a study file, for the log and study.json
  int seeds = 1;                    // runs per variant, with scene.seed = the scene's seed, +1, ...:
                                    // the figure is their mean, and its scatter is reported (a chute or
                                    // heap varies by 1-5 % from one packing to the next)
};

/// One variant's row.
struct StudyPoint {
  std::vector<std::string> values;  // one per varied key
  double figure = 0.0;              // NaN when the run did not report it; with seeds: their mean
  double error = 0.0;               // |figure - reference|, the figure's unit
  double error_pct = 0.0;           // 100 |figure - reference| / |reference| (NaN if reference is 0)
  double wall_s = 0.0;              // wall time of the run (results.json wall_time_s.total)
  bool ok = true;                   // the run ended normally and reported the figure
  bool is_reference = false;        // the finest variant, when it is the reference
  bool pareto = false;              // no other ok variant is both cheaper and closer
  // With several seeds: the runs that reported the figure, and its sample
  // standard deviation over them (NaN with fewer than two).
  int runs = 1;
  double scatter = 0.0;
};

struct StudyAnalysis {
  std::vector<StudyPoint> points;
  double reference = 0.0;
  std::optional<std::size_t> recommended;  // see analyseStudy
};

/// Errors, Pareto front and recommendation from the runs' figures and wall times.
/// With no `reference`, the last ok point is the reference (the finest variant).
/// Recommended: the cheapest ok variant that is within the tolerance together with
/// every ok variant listed after it (converged from there on: a variant that lands
/// near the reference by chance, with coarser and finer ones further off, is not
/// recommended).
StudyAnalysis analyseStudy(std::vector<StudyPoint> points, std::optional<double> reference, double tolerance_pct);

/// Runs the study; writes study.csv, study.json, study.png and one folder per run.
/// Returns an ExitCode (2 on bad input before any run; 130 when interrupted).
int runStudy(const StudyOptions& options, std::ostream& log);

/// A study file (assets/studies/*.toml): [study] scene, figure, reference ("finest"
/// or a number), tolerance_pct, set = [...], description, and [[study.vary]] key,
/// values. Throws SceneError naming the file and the key.
StudyOptions loadStudyFile(const std::filesystem::path& file);
/// True for a TOML file with a [study] table; a bare name is looked up in the
/// built-in studies (assets/studies/NAME.toml).
std::optional<std::filesystem::path> findStudyFile(const std::string& name_or_path);
std::filesystem::path builtinStudyDir();

}  // namespace rocklab::experiments
