#include "rocklab/experiments/cli.h"

#include <CLI/CLI.hpp>
#include <H5Cpp.h>

#include <iterator>
#include <new>
#include <csignal>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "agglomerate/agglomerate_cli.h"
#include "analysis/strength_groups.h"
#include "analysis/weibull_report.h"
#include "crusher/crusher_geometry_command.h"
#include "crusher/products_command.h"
#include "analysis/profiles_command.h"
#include "analysis/contrast_command.h"
#include "analysis/samples_command.h"
#include "analysis/sweeps_command.h"
#include "crusher/whiten_command.h"
#include "report/run_report.h"
#include "camera/render_run.h"
#include "common/json_text.h"
#include "common/quiet_log.h"
#include "rocklab/experiments/bond_calibration.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/experiments/shape.h"
#include "rocklab/experiments/study.h"
#include "rocklab/experiments/sweep.h"
#include "rocklab/sim/output/checkpoint.h"
#include "rocklab/sim/world.h"
#include "scene/scene_keys.h"
#include "sets/plan_file.h"

namespace rocklab::experiments {

namespace {

constexpr const char* kExamples = R"(
Examples:
  rocklab demo                                   # default scene end to end, outputs in out/demo
  rocklab list                                   # built-in scenes and studies
  rocklab run hopper --out runs/hopper           # a built-in scene by name
  rocklab run my.toml --set timestep.safety_factor=0.3 --set output.vtk=true
  rocklab check my.toml                          # validate and print the time-step audit only
  rocklab restart runs/hopper/checkpoint.h5 --set scene.end_time=2.0 --out runs/hopper2
  rocklab run drop                               # restitution of one pebble drop (results.json)
  rocklab calibrate drop --vary contact.damping_normal=0:0.4 --target restitution=0.72
  rocklab calibrate heap --vary materials.pebble.friction=0.2,0.3,0.4,0.5 --target angle_of_repose_deg=26.03
  rocklab sweep chute-30-clumps --vary experiment.inclination_deg=27,30,33   # one table + plot
  rocklab study drop-timestep                    # built-in study: error of restitution against run time
  rocklab study drop-timestep --plan runs/dt     # run list + Slurm script, nothing run; then:
  parallel --jobs 2 < runs/dt/runs.txt && rocklab collect runs/dt
  rocklab report out/demo                        # rebuild out/demo/report.html from its files
  rocklab study drop --vary timestep.safety_factor=0.8,0.4,0.2,0.1 --figure restitution --reference 0.7063
  rocklab render out/demo/run.h5 --camera top.toml --out out/demo-top    # re-render stored frames
  rocklab calibrate-bonds zwick-dense --fraction 40-60 --count 30 --jobs 2   # bond strength for Table 5.1
  rocklab scene-keys > docs/scene-format.md      # the scene file reference, from the readers
  rocklab crusher-geometry cone-crusher --set crusher.css=0.012   # chamber quantities + section.png
  rocklab whiten out/crusher --k1-mm 12 --k2-mm 25   # Whiten's model on a crusher run's feed
  rocklab products out/pbm out/bpm --label PBM --label BPM --out out/pbm-bpm   # product curves side by side
  rocklab profiles runs/inclined runs/vertical --out out/deposition   # chute marker profiles side by side
  rocklab samples runs/lab-s1 runs/lab-s2 runs/lab-s3 --out runs/lab   # a sweep's mean and scatter over samples
  rocklab samples runs/chute --over scene.seed   # the same over the seeds one sweep varies
  rocklab contrast runs/spheres/merged runs/clumps/merged   # ratio of two sample sets' means, variant by variant
  rocklab sweeps runs/css-large runs/css-medium --label "14.7 mm" --label "12.8 mm" --out runs/css-sizes   # sweeps as series

Exit codes: 0 done, 1 the run failed (its reason in results.json), shape or calibrate
missed what was asked (the reason in its results.json / calibration.json) or an
unexpected error, 2 bad input (nothing written), 3 stopped by the stability
watchdog, 4 a sweep or study finished but some runs failed (see its table),
130 interrupted by Ctrl-C, SIGTERM or SIGHUP (outputs so far are kept and readable;
a second signal ends the process at once).
Sweeps and studies run each variant as its own process of one thread, one per
core (--jobs N; --jobs 0 runs them here one after the other with --threads).
Units are SI everywhere (m, s, kg, N, Pa).)";

// The signals that ask a run to stop cleanly: Ctrl-C, and SIGTERM and SIGHUP, which
// schedulers (Slurm at its time limit) and closed terminals send. A signal the
// process was started ignoring stays ignored: `nohup rocklab run ...` must outlive
// its terminal (rocklab's own handler used to turn the hang-up into a stop).
constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};
volatile std::sig_atomic_t g_stop_signal_handled[std::size(kStopSignals)] = {};

extern "C" void onStopSignal(int) {
  requestStop();
  // A second stop signal, of any of the handled kinds, ends the process at once.
  for (std::size_t k = 0; k < std::size(kStopSignals); ++k)
    if (g_stop_signal_handled[k]) std::signal(kStopSignals[k], SIG_DFL);
}

/// While alive, SIGINT, SIGTERM and SIGHUP request a clean stop (checkpoint, results.json
/// with status "interrupted", exit 130), but for those the process ignores; the
/// handlers before it come back afterwards.
class StopOnSignals {
 public:
  StopOnSignals() {
    for (std::size_t k = 0; k < std::size(kStopSignals); ++k) {
      previous_[k] = std::signal(kStopSignals[k], onStopSignal);
      g_stop_signal_handled[k] = previous_[k] != SIG_IGN;
      if (previous_[k] == SIG_IGN) std::signal(kStopSignals[k], SIG_IGN);
    }
  }
  ~StopOnSignals() {
    for (std::size_t k = 0; k < std::size(kStopSignals); ++k) std::signal(kStopSignals[k], previous_[k]);
  }
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

 private:
  using Handler = void (*)(int);
  Handler previous_[std::size(kStopSignals)]{};
};

std::string firstLine(const std::string& s) { return s.substr(0, s.find('\n')); }

/// One line per TOML file of `dir`: its name and the first line of what `describe` says.
void listFiles(const std::string& title, const std::filesystem::path& dir,
               const std::function<std::string(const std::filesystem::path&)>& describe) {
  std::cout << title << " (" << dir.string() << "):\n";
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    std::string description;
    try {
      description = describe(f);
    } catch (const SceneError& e) {
      description = std::string("(invalid: ") + e.what() + ")";
    }
    const std::string name = f.stem().string();
    std::cout << "  " << name << std::string(name.size() < 20 ? 22 - name.size() : 2, ' ')
              << firstLine(description) << "\n";
  }
}

/// rocklab scene-keys: the scene reference as Markdown on stdout; with `check`,
/// compares it with that file instead (ctest "scene-keys").
int doSceneKeys(const std::string& check) {
  std::vector<std::string> problems;
  const std::string markdown = sceneKeysMarkdown(problems);
  for (const std::string& p : problems) std::cerr << "scene-keys: " << p << "\n";
  if (check.empty()) {
    std::cout << markdown;
    return problems.empty() ? kExitOk : kExitFailed;
  }
  std::ifstream in(check);
  std::stringstream committed;
  committed << in.rdbuf();
  if (!in || committed.str() != markdown) {
    std::cerr << "scene-keys: " << check
              << " is not the output of `rocklab scene-keys`; regenerate it: rocklab scene-keys > " << check
              << "\n";
    return kExitFailed;
  }
  return problems.empty() ? kExitOk : kExitFailed;
}

int doList() {
  listFiles("built-in scenes", builtinSceneDir(), [](const auto& f) { return sceneDescription(f); });
  listFiles("built-in studies, rocklab study NAME", builtinStudyDir(),
            [](const auto& f) { return loadStudyFile(f).description; });
  return kExitOk;
}

}  // namespace

namespace {

/// Everything the command line can set: CLI11 fills it, the commands read it.
struct CliArgs {
  std::string scene_arg, checkpoint_arg, run_file_arg, out_dir, camera_file, collect_dir;
  std::string film_camera_file;  // --camera of run, demo, restart, sweep, calibrate, study, calibrate-bonds
  std::string weibull_column = "strength_MPa", group_by, size_column;
  std::vector<std::string> overrides;
  int threads = 0;
  bool quiet = false, skip_complete = false, overwrite = false;
  // sweep, calibrate, study
  std::vector<std::string> vary, metrics;
  std::string x_over;
  std::string target, plan_dir, figure, reference;
  int iterations = 8, jobs = -1, seeds = 0;
  double tolerance = -1.0;
  SweepOptions::Slurm slurm;
  // shape
  ShapeOptions shape_options;
  bool no_preview = false;
  AgglomerateOptions agglomerate_options;
  // calibrate-bonds
  std::string fraction;
  double sigma0_mpa = 0, modulus = 0, trial_strength = 60e6;
  int count = 30, trials = 3, trial_orientations = 1;
  // whiten
  WhitenCommandOptions whiten;
  // products, profiles, samples (one of them a command line)
  RunComparisonOptions comparison;
  std::string contrast_op = "ratio";
  std::vector<std::string> where;
};

/// Threads and processes: 0 (the default) to 4096. CLI::NonNegativeNumber would
/// print its upper bound, the largest double, in 309 digits.
const CLI::Range kCountRange(0, 4096);

/// `text` (the value of option `what`) as a number; std::invalid_argument names
/// both (std::stod alone says only "stod").
double numberArgument(const std::string& what, const std::string& text) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw std::invalid_argument(what + ": '" + text + "' is not a number");
  return value;
}

void addRunOptions(CLI::App* c, CliArgs& a) {
  c->add_option("--out", a.out_dir, "Output directory (default: out/<scene name>)");
  c->add_option("--set", a.overrides, "Override a scene key, e.g. --set timestep.dt=1e-6 (TOML value)")
      ->take_all();
  c->add_option("--threads", a.threads, "OpenMP threads (default: all cores)")->check(kCountRange);
  c->add_option("--camera", a.film_camera_file,
                "Film the run with the [[cameras]] of this TOML file instead of the scene's (a chute's camera "
                "named by experiment.track_camera is tracked); e.g. a checkpoint's flow through the lab's camera");
  c->add_flag("--quiet", a.quiet,
              "Print only errors and warnings (no set-up lines, time-step audit, progress or summary)");
}

void addSetOptions(CLI::App* c, CliArgs& a) {
  c->add_option("--jobs", a.jobs,
                "Runs at once, each its own process of one thread (default: one per core); 0 = one after the "
                "other in this process, each with --threads")
      ->check(kCountRange);
  c->add_option("--plan", a.plan_dir,
                "Write the run list (runs.txt), a Slurm array script and a README into DIR and run nothing; "
                "`rocklab collect DIR` merges the runs afterwards");
  c->add_option("--slurm-time", a.slurm.time, "Slurm time limit per run (with --plan)")->capture_default_str();
  c->add_option("--slurm-mem", a.slurm.memory, "Slurm memory per run (with --plan)")->capture_default_str();
  c->add_option("--slurm-partition", a.slurm.partition, "Slurm partition (with --plan; default: the cluster's)");
}

// What --out, --threads, --quiet and the set options ask of a sweep or study.
void applySetOptions(const CliArgs& a, SweepOptions& so) {
  if (!a.plan_dir.empty() && !a.out_dir.empty() && a.plan_dir != a.out_dir)
    throw std::invalid_argument("--plan DIR is the output folder: give --plan or --out, not both");
  so.out_dir = a.plan_dir.empty() ? a.out_dir : a.plan_dir;
  so.plan_only = !a.plan_dir.empty();
  so.jobs = a.jobs;
  so.slurm = a.slurm;
  so.threads = a.threads;
  so.progress = !a.quiet;
}

void addSweepOptions(CLI::App* c, CliArgs& a) {
  c->add_option("scene", a.scene_arg,
                "Scene TOML file or built-in name, or a checkpoint.h5 that every run restarts from (e.g. a chute "
                "deposit run with experiment.stop_after = \"deposit\")")
      ->required();
  c->add_option("--vary", a.vary, "key=a,b,c: values to run (TOML values, as for --set)")->required();
  addRunOptions(c, a);
}

/// A command that sets finished runs or sets side by side (products, profiles,
/// samples, sweeps): the folders, a legend label a folder, the output folder (default out/NAME).
CLI::App* addRunComparison(CLI::App& app, CliArgs& a, const std::string& name, const std::string& what,
                           const std::string& folders, const std::string& outputs) {
  auto* c = app.add_subcommand(name, what);
  c->add_option("folders", a.comparison.runs, folders)->required();
  c->add_option("--label", a.comparison.labels, "A legend label a folder, in their order (default: the folders' names)")
      ->take_all();
  c->add_option("--out", a.out_dir, "Folder for " + outputs + " (default: out/" + name + ")");
  return c;
}

/// Every subcommand and its options, bound to the fields of `a`.
void addCommands(CLI::App& app, CliArgs& a) {
  auto* run = app.add_subcommand("run", "Run a scene file (or a built-in scene by name)");
  run->add_option("scene", a.scene_arg, "Scene TOML file or built-in name (see `rocklab list`)")->required();
  addRunOptions(run, a);
  auto* demo = app.add_subcommand("demo", "Run the default demo scene end to end");
  addRunOptions(demo, a);
  auto* restart = app.add_subcommand("restart", "Continue a run from its checkpoint.h5, bit for bit");
  restart->add_option("checkpoint", a.checkpoint_arg, "checkpoint.h5 written by an earlier run")->required();
  addRunOptions(restart, a);
  for (CLI::App* c : {run, restart})  // a set's run lines (runs.txt) skip what is done
    c->add_flag("--skip-complete", a.skip_complete,
                "Do nothing when --out already holds a completed run (results.json status \"completed\")");
  for (CLI::App* c : {run, demo, restart})
    c->add_flag("--overwrite", a.overwrite,
                "Replace an earlier run in --out (its files are removed first); without it such a folder is "
                "refused");
  auto* check = app.add_subcommand("check", "Validate a scene and print its time-step audit without running");
  check->add_option("scene", a.scene_arg, "Scene TOML file or built-in name")->required();
  check->add_option("--set", a.overrides, "Override a scene key")->take_all();
  app.add_subcommand("list", "List the built-in scenes and studies");
  auto* crusher = app.add_subcommand(
      "crusher-geometry", "Print a cone crusher scene's derived chamber (Eq 6-1..6-9) and draw its closed-side section");
  crusher->add_option("scene", a.scene_arg, "Scene TOML file or built-in name with a [crusher] table")->required();
  crusher->add_option("--set", a.overrides, "Override a scene key, e.g. --set crusher.css=0.012")->take_all();
  crusher->add_option("--out", a.out_dir, "Output directory for section.png and results.json (default: out/<scene name>-geometry)");
  auto* whiten = app.add_subcommand(
      "whiten", "Whiten's classification-breakage model (Eq 3-20) on a crusher run's feed, beside its DEM product");
  whiten->add_option("run", a.collect_dir, "Folder of a finished crusher run (its results.json)")->required();
  whiten->add_option("--k1-mm", a.whiten.k1_mm, "k1 of Eq 3-21..3-23, mm (default: the run's, its chamber's closed-side gap)");
  whiten->add_option("--k2-mm", a.whiten.k2_mm, "k2, mm (default: the run's, its chamber's open-side setting)");
  whiten->add_option("--exponent", a.whiten.exponent, "Exponent of Eq 3-22 (default 2, as the study prints it)");
  whiten->add_option("--mode", a.whiten.mode, "Breakage split: triple (60/30/10 %) or equal (default: the run's)");
  whiten->add_option("--out", a.out_dir, "Folder for whiten.json and whiten.png (default: the run's folder)");
  addRunComparison(app, a, "products",
                   "Product curves of finished crusher runs on one sieve chart, with their P50, P80 and breakages",
                   "Folders of finished crusher runs (their results.json)",
                   "products.csv, products.json and product_curves.png");
  addRunComparison(app, a, "profiles",
                   "Marker velocity profiles and discharge curves of finished chute runs side by side, with their "
                   "clearance",
                   "Folders of finished chute runs (their results.json)", "profiles.csv, profiles.json and the plots");
  auto* samples = addRunComparison(
      app, a, "samples",
      "Sweeps of the same variants on different samples (a seed or a deposit each) merged: every figure's mean, "
      "sample standard deviation and range a variant",
      "Folders of finished sweeps, one a sample (their plan.json and sweep.csv)",
      "samples.csv, samples.json and samples.png");
  samples->add_option("--figure", a.figure,
                      "The sweep.csv column to plot and print (default: the first with numbers)");
  samples->add_option("--over", a.group_by,
                      "A key the sweeps vary whose values are samples (e.g. scene.seed; default: a sample a folder)");
  auto* contrast = addRunComparison(
      app, a, "contrast",
      "Two sets of samples (folders of `rocklab samples`) compared variant by variant: the ratio or difference of "
      "every figure's means, with its scatter from both sets' standard deviations",
      "Two folders written by `rocklab samples`, A then B", "contrast.csv, contrast.json and contrast.md");
  contrast->add_option("--op", a.contrast_op, "ratio (A / B, the default) or difference (A - B)")
      ->check(CLI::IsMember({"ratio", "difference"}));
  contrast->add_option("--where", a.where,
                       "KEY=VALUE: only the variants with that value of a key (for a key only one set varies, e.g. "
                       "--where 'walls.top.corner=[0,0,0.05]')")
      ->take_all();
  auto* sweeps = addRunComparison(
      app, a, "sweeps",
      "Finished sweeps of the same keys side by side, a series each (e.g. one deposit a clump size): their rows in "
      "one table and one figure against the first key (over each row's --x-over figure)",
      "Folders of finished sweeps, one a series (their plan.json and sweep.csv)",
      "sweeps.csv, sweeps.json and sweeps.png");
  sweeps->add_option("--figure", a.figure, "The sweep.csv column to plot (default: the first with numbers)");
  auto* keys = app.add_subcommand("scene-keys", "Print the scene file reference (every table and key) as Markdown");
  keys->add_option("--check", a.collect_dir, "Compare with this file instead of printing (exit 1 if it differs)");
  auto* render = app.add_subcommand("render", "Re-render the frames stored in a run.h5 (scene cameras or --camera file)");
  render->add_option("run", a.run_file_arg, "run.h5 written by an earlier run")->required();
  render->add_option("--camera", a.camera_file, "TOML file with [[cameras]] tables (default: the scene's cameras)");
  render->add_option("--out", a.out_dir, "Output directory (default: the run file's folder)");
  auto* sweep = app.add_subcommand("sweep", "Run a scene for every combination of --vary values; writes sweep.csv and sweep.png");
  addSweepOptions(sweep, a);
  sweep->add_option("--metric", a.metrics, "results.json figure to tabulate, dotted path (default: the experiment's)");
  sweep->add_option("--x-over", a.x_over,
                    "Plot against the first --vary key's value divided by this results.json figure of each run "
                    "(e.g. clump_shapes.0.equivalent_diameter_m: CSS / d_eq); tabulated too");
  addSetOptions(sweep, a);
  auto* calibrate = app.add_subcommand(
      "calibrate", "Find the value of one key that gives a target figure (list: interpolate; lo:hi range: bisect)");
  addSweepOptions(calibrate, a);
  calibrate->add_option("--target", a.target, "metric=value, e.g. angle_of_repose_deg=26.03")->required();
  calibrate->add_option("--iterations", a.iterations, "Bisection steps for a lo:hi range")->check(CLI::PositiveNumber);
  auto* study = app.add_subcommand(
      "study", "Error against run time: a figure for every --vary combination, against the finest or a lab value");
  study->add_option("scene", a.scene_arg, "Scene file or name, or a study file / built-in study (assets/studies)")
      ->required();
  study->add_option("--vary", a.vary, "key=a,b,c from the cheapest to the finest value (replaces the study file's)");
  study->add_option("--figure", a.figure, "results.json figure, dotted path (e.g. restitution, tracking.rms_error_pct)");
  study->add_option("--reference", a.reference, "finest (default: the last variant) or a lab value");
  study->add_option("--tolerance", a.tolerance, "error (%) the recommended variant may have (default 5)")
      ->check(CLI::PositiveNumber);
  study->add_option("--seeds", a.seeds,
                    "runs per variant with seeds from the scene's up: mean, seed scatter and whether the errors "
                    "exceed it (default: the study file's, else 1)")
      ->check(CLI::PositiveNumber);
  addRunOptions(study, a);
  addSetOptions(study, a);
  auto* collect = app.add_subcommand("collect", "Merge the finished runs of a sweep or study folder into its table, "
                                                "plot and recommendation (failed and missing runs listed)");
  collect->add_option("dir", a.collect_dir, "Folder of a sweep or study (holds plan.json)")->required();

  auto* report = app.add_subcommand("report", "Rebuild report.html of a run folder, or of a sweep, study or calibration folder");
  report->add_option("dir", a.collect_dir, "Folder of a run (holds results.json) or of a set (plan.json, runs/)")->required();

  auto* weibull = app.add_subcommand(
      "weibull", "Weibull analysis of a batch of crushing runs (a sweep folder): weibull.json, the Weibull plot and the force-displacement curves of its runs");
  weibull->add_option("dir", a.collect_dir, "Folder of the batch's sweep (holds sweep.csv)")->required();
  weibull->add_option("--column", a.weibull_column, "sweep.csv column with the strengths in MPa")
      ->capture_default_str();
  weibull->add_option("--group-by", a.group_by,
                      "Statistics per value of this column (a varied key, e.g. particles.0.r0): "
                      "strength_groups.csv/.json/.png");
  weibull->add_option("--size-column", a.size_column,
                      "With --group-by: fit the size effect sigma_av = a d^b (Eq 5-5) with d = this column's "
                      "mean per group (a column ending in _m is fitted in mm)");

  auto* bonds = app.add_subcommand(
      "calibrate-bonds",
      "Bond strength that reproduces a lab fraction's Weibull sigma0 and m (trials B0 = B sigma0/sigma, then a batch)");
  bonds->add_option("scene", a.scene_arg, "Crushing scene (with [bonds]) file or built-in name")->required();
  bonds->add_option("--fraction", a.fraction, "Table 5.1 fraction, mm: " + tableFiveOneNames());
  bonds->add_option("--sigma0", a.sigma0_mpa, "Target 37 % strength, MPa (instead of --fraction)");
  bonds->add_option("--modulus", a.modulus, "Target Weibull modulus m (instead of --fraction)");
  bonds->add_option("--trial-strength", a.trial_strength, "Bond strength of the first trial, Pa")
      ->capture_default_str();
  bonds->add_option("--trials", a.trials, "Trials at most, each scaling B by sigma0 / sigma")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  bonds->add_option("--trial-orientations", a.trial_orientations,
                    "Random orientations per trial (scene.seed after the batch's): the trial's strength is their "
                    "mean, and their spread is taken out of the bonds' Weibull modulus")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000));
  bonds->add_option("--count", a.count, "Agglomerates in the batch")->capture_default_str()->check(CLI::Range(3, 100000));
  addRunOptions(bonds, a);
  addSetOptions(bonds, a);

  auto* shape = app.add_subcommand("shape", "Mesh (STL/PLY/OBJ) -> checked mass properties and a clump of spheres with its error");
  shape->add_option("mesh", a.shape_options.mesh, "Mesh file (with --generate: the mesh file to write, .stl/.ply/.obj)")->required();
  shape->add_option("--out", a.shape_options.out_dir, "Output directory (clump.txt, clump.toml, preview.png, results.json)")->required();
  shape->add_option("--method", a.shape_options.method, "surface (tangent spheres grown from the surface) | medial (medial axis)");
  shape->add_option("--spheres", a.shape_options.spheres, "Largest number of spheres");
  shape->add_option("--tolerance", a.shape_options.tolerance, "Stop when the uncovered volume fraction is below this (0 = off)");
  shape->add_option("--unit", a.shape_options.unit, "Unit of the file's coordinates: m | mm");
  shape->add_option("--fill-holes", a.shape_options.fill_holes,
                    "Close holes of the scan whose rim has at most N edges by a minimum-area patch (0 = none: an open mesh is an error)")
      ->check(CLI::Range(0, 100000));
  shape->add_option("--size", a.shape_options.size, "Scale to this size (m); see --size-kind");
  shape->add_option("--size-kind", a.shape_options.size_kind, "equivalent (equal-volume sphere diameter) | sieve");
  shape->add_option("--density", a.shape_options.density, "kg/m^3 (mass and inertia in clump.toml)");
  shape->add_option("--min-radius", a.shape_options.min_radius, "Smallest member radius, fraction of the equivalent diameter");
  shape->add_option("--touch", a.shape_options.touch, "Surface method: node tolerance, fraction of the equivalent diameter");
  shape->add_option("--grid", a.shape_options.grid, "Inside-grid cells along the longest extent");
  shape->add_option("--generate", a.shape_options.generate, "Make a seeded scan-like mesh first: pebble | crushed | flake");
  shape->add_option("--seed", a.shape_options.seed, "Seed of --generate and of the surface samples");
  shape->add_option("--sweep", a.shape_options.sweep, "Sphere counts for the error table, e.g. 1,2,4,8,16")->delimiter(',');
  shape->add_flag("--pile", a.shape_options.pile, "With --sweep: time a settling pile of clumps for each count");
  shape->add_option("--pile-clumps", a.shape_options.pile_clumps, "Clumps in the pile");
  shape->add_option("--pile-time", a.shape_options.pile_time, "Simulated time of the pile (s)");
  shape->add_flag("--no-preview", a.no_preview, "Do not render preview.png");
  addAgglomerateCommand(app, a.agglomerate_options, a.no_preview);
}

int studyCommand(const CliArgs& a) {
  const StopOnSignals stop_on_signals;
  try {
    StudyOptions so;
    if (const auto file = findStudyFile(a.scene_arg)) so = loadStudyFile(*file);
    else so.runs.scene = a.scene_arg;
    so.runs.overrides.insert(so.runs.overrides.end(), a.overrides.begin(), a.overrides.end());
    if (!a.vary.empty()) so.runs.vary.clear();
    for (const std::string& v : a.vary) so.runs.vary.push_back(parseVary(v));
    if (!a.figure.empty()) so.figure = a.figure;
    if (a.reference == "finest") so.reference.reset();
    else if (!a.reference.empty())
      so.reference = numberArgument("--reference (finest or a lab value)", a.reference);
    if (a.tolerance > 0) so.tolerance_pct = a.tolerance;
    if (a.seeds > 0) so.seeds = a.seeds;
    applySetOptions(a, so.runs);
    return runStudy(so, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
}

int sweepCommand(const CliArgs& a, bool calibrate) {
  SweepOptions so;
  so.scene = a.scene_arg;
  so.overrides = a.overrides;
  so.metrics = a.metrics;
  so.x_over = a.x_over;
  so.out_dir = a.out_dir;
  so.threads = a.threads;
  so.progress = !a.quiet;
  const StopOnSignals stop_on_signals;
  try {
    for (const std::string& v : a.vary) so.vary.push_back(parseVary(v));
    if (!calibrate) {
      applySetOptions(a, so);
      return runSweep(so, std::cerr);
    }
    CalibrateOptions co;
    co.sweep = so;
    co.iterations = a.iterations;
    const auto eq = a.target.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("--target '" + a.target + "': expected metric=value");
    co.target_metric = a.target.substr(0, eq);
    co.target = numberArgument("--target " + a.target, a.target.substr(eq + 1));
    return runCalibrate(co, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
}

/// calibrate-bonds: the target from Table 5.1 (--fraction) or given (--sigma0, --modulus).
int calibrateBondsCommand(const CliArgs& a) {
  BondCalibrationOptions c;
  c.runs.scene = a.scene_arg;
  c.runs.overrides = a.overrides;
  c.trial_strength_Pa = a.trial_strength;
  c.max_trials = a.trials;
  c.count = a.count;
  c.trial_orientations = a.trial_orientations;
  try {
    applySetOptions(a, c.runs);
    if (!a.fraction.empty()) {
      const auto f = tableFiveOneFraction(a.fraction);
      if (!f)
        throw std::invalid_argument("--fraction " + a.fraction + ": Table 5.1 has " + tableFiveOneNames());
      c.target = *f;
    } else {
      c.target.name = "given";
    }
    if (a.sigma0_mpa > 0) c.target.sigma0_MPa = a.sigma0_mpa;
    if (a.modulus > 0) c.target.modulus = a.modulus;
    if (!(c.target.sigma0_MPa > 0 && c.target.modulus > 0))
      throw std::invalid_argument("give --fraction (" + tableFiveOneNames() + ") or --sigma0 and --modulus");
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: calibrate-bonds: " << e.what() << "\n";
    return kExitBadInput;
  }
  const StopOnSignals stop_on_signals;
  return runBondCalibration(c, std::cerr);
}

/// True (and says so) when DIR holds the results.json of a completed run.
bool isCompleteRun(const std::filesystem::path& dir) {
  if (!detail::runCompleted(dir)) return false;
  std::cerr << "rocklab: " << (dir / "results.json").string() << " is complete; not run again\n";
  return true;
}

/// run, demo, restart and check: one scene, loaded and checked, then run.
int sceneCommand(const CliArgs& a, const std::string& command) {
  // A finished run named by --out is skipped before its scene is loaded: loading may
  // build a dense agglomerate (seconds to tens of seconds), which a batch re-run of
  // hundreds of finished runs should not pay.
  if (a.skip_complete && !a.out_dir.empty() && isCompleteRun(a.out_dir)) return kExitOk;
  Scene scene;
  RunOptions options;
  options.threads = a.threads;
  options.progress = !a.quiet;
  options.earlier_run = a.overwrite ? EarlierRun::Replace : EarlierRun::Refuse;
  try {
    if (command == "restart") {
      // The checkpoint carries the scene text it was run with.
      const sim::output::Checkpoint cp = sim::output::readCheckpoint(a.checkpoint_arg);
      scene = loadSceneText(cp.scene_text, a.checkpoint_arg + ":/scene", a.overrides,
                            std::filesystem::path(a.checkpoint_arg).parent_path());
      scene.source = a.checkpoint_arg;  // what the run's messages name
      options.restart = a.checkpoint_arg;
    } else {
      const std::string name = command == "demo" ? "demo" : a.scene_arg;
      scene = loadScene(resolveScene(name), a.overrides);
    }
  } catch (const SceneError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const sim::output::CheckpointError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }

  if (command == "check") {
    try {
      // Built as a run builds it, bonds included: their springs set the step of a bonded scene.
      sim::World world(scene.model, scene.spheres, scene.clumps, scene.bonds, 1);
      std::cout << scene.source.string() << ": valid; " << scene.spheres.size() << " spheres, "
                << scene.clumps.size() << " clumps, " << scene.model.walls.size() << " walls\n"
                << world.timestepAudit().describe(scene.model.timestep) << "\n";
      return kExitOk;
    } catch (const std::invalid_argument& e) {
      std::cerr << "error: " << scene.source.string() << ": " << e.what() << "\n";
      return kExitBadInput;
    }
  }

  options.out_dir = a.out_dir.empty() ? std::filesystem::path("out") / scene.run.name : std::filesystem::path(a.out_dir);
  if (a.skip_complete && isCompleteRun(options.out_dir)) return kExitOk;
  const StopOnSignals stop_on_signals;
  detail::QuietLogBuffer quiet(std::cerr);
  std::ostream quiet_log(&quiet);
  return runScene(std::move(scene), options, a.quiet ? quiet_log : std::cerr);
}

/// The command line parsed and run; `name` is set to the subcommand's name once known.
int runCliUnguarded(int argc, const char* const* argv, std::string& name) {
  CLI::App app{"rocklab: DEM workbench for laboratory experiments on rock flow and breakage"};
  app.footer(kExamples);
  app.require_subcommand(1);
  app.set_version_flag("--version", "rocklab 0.1.0");
  CliArgs a;
  addCommands(app, a);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }
  if (const auto subcommands = app.get_subcommands(); !subcommands.empty()) name = "rocklab " + subcommands.front()->get_name();

  // --camera FILE: the file's cameras as one more --set, so that the run's scene text,
  // its checkpoint and a set's run lines carry them like any override.
  if (!a.film_camera_file.empty()) {
    try {
      a.overrides.push_back(cameraFileOverride(a.film_camera_file));
    } catch (const SceneError& e) {
      std::cerr << "error: --camera: " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  if (app.got_subcommand("list")) return doList();
  if (app.got_subcommand("crusher-geometry"))
    return runCrusherGeometry({a.scene_arg, a.overrides, a.out_dir}, std::cout, std::cerr);
  if (app.got_subcommand("scene-keys")) return doSceneKeys(a.collect_dir);
  if (app.got_subcommand("whiten")) {
    a.whiten.run_dir = a.collect_dir;
    a.whiten.out_dir = a.out_dir;
    return runWhitenCommand(a.whiten, std::cout, std::cerr);
  }
  for (const std::string command : {"products", "profiles", "samples", "sweeps", "contrast"}) {
    if (!app.got_subcommand(command)) continue;
    a.comparison.out_dir = a.out_dir.empty() ? std::filesystem::path("out") / command : std::filesystem::path(a.out_dir);
    if (command == "contrast")
      return runContrastCommand(
          {a.comparison, a.contrast_op == "difference" ? ContrastOp::Difference : ContrastOp::Ratio, a.where},
          std::cout, std::cerr);
    if (command == "products") return runProductsCommand(a.comparison, std::cout, std::cerr);
    if (command == "profiles") return runProfilesCommand(a.comparison, std::cout, std::cerr);
    if (command == "sweeps") return runSweepsCommand(a.comparison, a.figure, std::cout, std::cerr);
    return runSamplesCommand(a.comparison, a.figure, a.group_by, std::cout, std::cerr);
  }
  if (app.got_subcommand("collect")) return collectSet(a.collect_dir, std::cerr);
  if (app.got_subcommand("report")) return detail::reportCommand(a.collect_dir, std::cerr);
  if (app.got_subcommand("weibull")) {
    if (a.group_by.empty()) {
      if (!a.size_column.empty()) {
        std::cerr << "error: weibull: --size-column needs --group-by (the sizes are fitted over the groups)\n";
        return kExitBadInput;
      }
      return weibullCommand(a.collect_dir, a.weibull_column, std::cerr);
    }
    return strengthGroupsCommand(a.collect_dir, {a.weibull_column, a.group_by, a.size_column}, std::cerr);
  }
  if (app.got_subcommand("shape")) {
    a.shape_options.preview = !a.no_preview;
    return runShape(a.shape_options, std::cerr);
  }
  if (app.got_subcommand("agglomerate")) {
    a.agglomerate_options.preview = !a.no_preview;
    return runAgglomerate(a.agglomerate_options, std::cerr);
  }
  if (app.got_subcommand("render")) return renderRun({a.run_file_arg, a.camera_file, a.out_dir}, std::cerr);
  if (app.got_subcommand("study")) return studyCommand(a);
  if (app.got_subcommand("calibrate-bonds")) return calibrateBondsCommand(a);
  if (app.got_subcommand("sweep") || app.got_subcommand("calibrate"))
    return sweepCommand(a, app.got_subcommand("calibrate"));

  for (const char* command : {"restart", "demo", "check"})
    if (app.got_subcommand(command)) return sceneCommand(a, command);
  return sceneCommand(a, "run");
}

}  // namespace

int runCli(int argc, const char* const* argv) {
  // The last line of defence: whatever a command did not catch ends here with a
  // message and a documented exit code, never in std::terminate. Causes found
  // are fixed where they arise, with the file and value named there.
  std::string command = "rocklab";
  try {
    return runCliUnguarded(argc, argv, command);
  } catch (const std::bad_alloc&) {
    std::cerr << "error: " << command
              << ": out of memory (the input asks for more memory than this machine can give)\n";
  } catch (const H5::Exception& e) {
    std::cerr << "error: " << command << ": HDF5: " << e.getDetailMsg() << " (" << e.getFuncName() << ")\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << command << ": " << e.what() << "\n";
  } catch (...) {
    std::cerr << "error: " << command << ": stopped by an unexpected error\n";
  }
  return kExitFailed;
}

}  // namespace rocklab::experiments
