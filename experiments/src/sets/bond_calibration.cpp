// `rocklab calibrate-bonds`: the bond-strength calibration of experiments.md §f.6
// (see bond_calibration.h). The trials are runs of the scene with one constant
// bond strength; the batch is a sweep over scene.seed with the Weibull draw per
// agglomerate; its fit is `rocklab weibull`'s.
#include "rocklab/experiments/bond_calibration.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "analysis/sample_statistics.h"
#include "analysis/sweep_table.h"
#include "analysis/weibull.h"
#include "analysis/weibull_report.h"
#include "common/atomic_file.h"
#include "common/json_text.h"
#include "report/set_report.h"
#include "rocklab/experiments/run.h"
#include "sets/run_set.h"

namespace rocklab::experiments {

namespace {

// Table 5.1 of the study (experiments.md §e): the lab's calibration inputs.
const LabFraction kTableFiveOne[] = {
    {"14-28", 20.12, 20.02, 0.9608, 3.0895},
    {"30-37.5", 12.61, 11.26, 0.9644, 3.2859},
    {"40-60", 9.49, 8.47, 0.9882, 2.4398},
};

/// The scene's assignments for bonds of one strength (Pa), normal = shear (§f.6 [I]).
std::vector<std::string> constantStrength(double strength) {
  return {"bonds.strength_distribution = \"constant\"", "bonds.tensile_strength = " + detail::cell(strength),
          "bonds.shear_strength = " + detail::cell(strength)};
}

double percentOff(double value, double target) { return 100.0 * (value - target) / target; }

/// "+3.2 %" / "-24 %": a signed percentage for the log.
std::string signedPercent(double pct) {
  std::ostringstream s;
  s << std::showpos << std::setprecision(3) << pct << " %";
  return s.str();
}

/// One trial: the scene with constant bonds of strength `bond` crushed once per seed
/// (scene.seed turns a random orientation), as a sweep in `dir`.
struct TrialResult {
  std::vector<double> strengths_Pa;
  double mean_strength_Pa = 0, cov = 0, wall_s = 0;
};

int runTrial(const SweepOptions& runs, double bond, const std::vector<std::string>& seeds,
             const std::filesystem::path& dir, TrialResult& r, std::ostream& log) {
  SweepOptions o = runs;
  for (const std::string& s : constantStrength(bond)) o.overrides.push_back(s);
  o.vary = {{"scene.seed", seeds}};
  o.out_dir = dir;
  o.plan_only = false;  // the trials run even when the batch is only planned
  o.metrics = {"strength_MPa", "wall_time_s.total"};
  const int code = runSweep(o, log);
  if (code != kExitOk) return code;
  const SweepTable t = readSweepTable(dir);
  const std::size_t strength = t.column("strength_MPa"), wall = t.column("wall_time_s.total");
  for (const auto& row : t.rows) {
    const auto v = SweepTable::numberIn(row, strength);
    if (!v || !(*v > 0)) return kExitRunsFailed;  // a crush without a strength
    r.strengths_Pa.push_back(*v * 1e6);
    r.wall_s += SweepTable::numberIn(row, wall).value_or(0.0);
  }
  if (r.strengths_Pa.size() != seeds.size()) return kExitRunsFailed;
  const SampleStatistics stats = sampleStatistics(r.strengths_Pa);
  r.mean_strength_Pa = stats.mean;
  if (stats.n > 1) r.cov = stats.cov();
  return kExitOk;
}

/// The batch's bond strengths. The study's rule (§f.6) draws them with the lab's m:
/// right when the agglomerate's strength is B times a constant. When it is B times an
/// orientation factor X of spread CoV_X (measured by the trials), the strengths of
/// independent B and X spread as 1 + CoV^2 = (1 + CoV_B^2)(1 + CoV_X^2), so the bonds
/// get the modulus m_B whose CoV_B makes CoV the lab's; and since the trials put the
/// mean over orientations at B X = sigma0, B0 = B Gamma(1 + 1/m) / Gamma(1 + 1/m_B)
/// makes the batch's mean the lab's sigma0 Gamma(1 + 1/m). Below a 2 % bond CoV the
/// orientations alone give the lab's spread: constant bonds (m_B infinite).
struct BondSpread {
  bool constant = false;
  double modulus = 0;    // m_B (when not constant)
  double b0_factor = 1;  // B0 = trial B * factor
};

BondSpread bondSpreadFor(double lab_modulus, double orientation_cov) {
  if (!(orientation_cov > 0)) return {false, lab_modulus, 1.0};
  const double lab_cov = weibullCov(lab_modulus);
  const double bond_cov2 = (1 + lab_cov * lab_cov) / (1 + orientation_cov * orientation_cov) - 1;
  if (bond_cov2 < 0.02 * 0.02) return {true, 0.0, weibullMeanFactor(lab_modulus)};
  const double m_b = weibullModulusForCov(std::sqrt(bond_cov2));
  return {false, m_b, weibullMeanFactor(lab_modulus) / weibullMeanFactor(m_b)};
}

}  // namespace

std::optional<LabFraction> tableFiveOneFraction(const std::string& name) {
  for (const LabFraction& f : kTableFiveOne)
    if (f.name == name) return f;
  return std::nullopt;
}

std::string tableFiveOneNames() {
  std::string names;
  for (const LabFraction& f : kTableFiveOne) names += (names.empty() ? "" : ", ") + f.name;
  return names;
}

int runBondCalibration(const BondCalibrationOptions& c, std::ostream& log) {
  if (!c.runs.vary.empty()) {
    log << "error: calibrate-bonds: no --vary (the trials vary the bond strength, the batch scene.seed)\n";
    return kExitBadInput;
  }
  if (!(c.target.sigma0_MPa > 0) || !(c.target.modulus > 0) || !(c.trial_strength_Pa > 0) || c.count < 3 ||
      c.max_trials < 1) {
    log << "error: calibrate-bonds: need sigma0 > 0 MPa, modulus > 0, a trial strength > 0 Pa, at least one "
           "trial and a batch of at least 3\n";
    return kExitBadInput;
  }
  // Every run's scene is checked before the first one starts (nothing written on bad input).
  SweepOptions trial = c.runs;
  for (const std::string& s : constantStrength(c.trial_strength_Pa)) trial.overrides.push_back(s);
  Scene scene;
  try {
    scene = detail::sceneFor(trial, {});
  } catch (const SceneError& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (scene.bonds.empty()) {
    log << "error: calibrate-bonds: scene '" << scene.run.name << "' has no bonds to calibrate\n";
    return kExitBadInput;
  }
  const std::filesystem::path dir = detail::outDirFor(c.runs, scene, "-calibrate-bonds");
  std::filesystem::create_directories(dir);
  const double target_pa = c.target.sigma0_MPa * 1e6;
  log << "calibrate-bonds " << scene.run.name << ": bond strength for "
      << (c.target.name == "given" ? std::string("the given target")
                                   : "the lab's " + c.target.name + " mm fraction (Table 5.1)")
      << ", sigma0 = " << c.target.sigma0_MPa << " MPa, m = " << c.target.modulus << "\n";

  // Trials: B_{k+1} = B_k sigma0 / sigma_k (§f.6 step 4, [R]), sigma_k the mean over the
  // trial's orientations (seeds after the batch's, so no batch run repeats a trial's).
  std::vector<std::string> trial_seeds;
  for (int j = 0; j < c.trial_orientations; ++j) trial_seeds.push_back(std::to_string(c.first_seed + c.count + j));
  nlohmann::json trials = nlohmann::json::array();
  std::vector<std::vector<std::string>> rows;
  double bond = c.trial_strength_Pa, calibrated = NAN, orientation_cov = 0.0;
  for (int k = 0; k < c.max_trials; ++k) {
    const std::string name = "trial-" + std::to_string(k + 1);
    TrialResult r;
    const int code = runTrial(c.runs, bond, trial_seeds, dir / name, r, log);
    if (code == kExitInterrupted) return kExitInterrupted;
    if (code != kExitOk) {
      log << "calibrate-bonds: " << name << " (B = " << bond * 1e-6 << " MPa) failed: exit " << code << "; see "
          << (dir / name).string() << "\n";
      return kExitRunsFailed;
    }
    const double sigma = r.mean_strength_Pa;
    const double next = bond * target_pa / sigma;
    log << "calibrate-bonds: trial " << k + 1 << ": B = " << bond * 1e-6 << " MPa -> sigma = " << sigma * 1e-6
        << " MPa";
    if (r.strengths_Pa.size() > 1)
      log << " (mean of " << r.strengths_Pa.size() << " orientations, CoV " << std::setprecision(3) << r.cov
          << std::setprecision(6) << ")";
    log << " (" << signedPercent(percentOff(sigma, target_pa)) << " off sigma0), " << r.wall_s
        << " s; B0 = B sigma0 / sigma = " << next * 1e-6 << " MPa\n";
    nlohmann::json strengths = nlohmann::json::array();
    for (double v : r.strengths_Pa) strengths.push_back(v * 1e-6);
    trials.push_back({{"bond_strength_Pa", bond},
                      {"strength_MPa", sigma * 1e-6},
                      {"orientation_strengths_MPa", strengths},
                      {"orientation_cov", r.cov},
                      {"off_target_pct", percentOff(sigma, target_pa)},
                      {"next_bond_strength_Pa", next},
                      {"wall_time_s", r.wall_s}});
    rows.push_back({std::to_string(k + 1), detail::cell(bond * 1e-6), detail::cell(sigma * 1e-6),
                    detail::cell(r.cov), detail::cell(percentOff(sigma, target_pa)), detail::cell(next * 1e-6),
                    detail::cell(r.wall_s)});
    calibrated = next;
    orientation_cov = r.cov;
    if (std::abs(percentOff(sigma, target_pa)) <= c.tolerance_pct) {
      calibrated = bond;  // this trial is on target: keep its B
      break;
    }
    bond = next;
  }
  detail::writeTable({"trial", "bond_strength_MPa", "strength_MPa", "orientation_cov", "off_sigma0_pct", "B0_MPa",
                      "wall_s"},
                     rows, dir / "calibration.csv", log);
  const BondSpread spread = bondSpreadFor(c.target.modulus, c.trial_orientations > 1 ? orientation_cov : 0.0);
  const double b0 = calibrated * spread.b0_factor;
  if (c.trial_orientations > 1) {
    log << "calibrate-bonds: orientation CoV " << orientation_cov << " against the lab's " << weibullCov(c.target.modulus)
        << " (m = " << c.target.modulus << "): ";
    if (!(orientation_cov > 0))
      log << "the orientations gave one strength (is the specimen's orientation \"random\"?): ";
    if (spread.constant)
      log << "the orientations alone scatter as much as the lab, so every agglomerate gets the same bonds, B = "
          << b0 * 1e-6 << " MPa (the lab's m cannot be reached with this agglomerate)\n";
    else
      log << "bond modulus m_B = " << spread.modulus << ", B0 = " << b0 * 1e-6 << " MPa (the batch's mean on the lab's)\n";
  }

  // The batch: one Weibull-drawn strength per agglomerate, modulus m, 37 % value B0.
  SweepOptions batch = c.runs;
  batch.out_dir = dir / "batch";
  for (const std::string& s : constantStrength(b0)) batch.overrides.push_back(s);
  if (!spread.constant) {
    batch.overrides.push_back("bonds.strength_distribution = \"weibull_per_agglomerate\"");
    batch.overrides.push_back("bonds.weibull_modulus = " + detail::cell(spread.modulus));
  }
  std::vector<std::string> seeds;
  for (int k = 0; k < c.count; ++k) seeds.push_back(std::to_string(c.first_seed + k));
  batch.vary = {{"scene.seed", seeds}};
  batch.metrics = {"strength_MPa", "peak_force_N", "zwick.platen_gap_at_peak_m", "bonds_broken",
                   "zwick.agglomerate_bond_strength_Pa", "wall_time_s.total"};
  log << "calibrate-bonds: batch of " << c.count << " with B0 = " << b0 * 1e-6 << " MPa, m = "
      << (spread.constant ? std::string("constant") : detail::cell(spread.modulus)) << " into " << batch.out_dir.string() << "\n";
  const int batch_code = runSweep(batch, log);
  nlohmann::json j;
  j["target"] = {{"fraction_mm", c.target.name},
                 {"sigma0_MPa", c.target.sigma0_MPa},
                 {"mean_MPa", c.target.mean_MPa},
                 {"r2", c.target.r2},
                 {"weibull_m", c.target.modulus},
                 {"source", "Table 5.1 (experiments.md §e)"}};
  j["trials"] = trials;
  j["trial_orientations"] = c.trial_orientations;
  j["trial_bond_strength_Pa"] = calibrated;
  j["calibrated_bond_strength_Pa"] = b0;
  j["bond_weibull_m"] = spread.constant ? nlohmann::json(nullptr) : nlohmann::json(spread.modulus);
  j["bond_strength_distribution"] = spread.constant ? "constant" : "weibull_per_agglomerate";
  j["orientation_cov"] = c.trial_orientations > 1 ? nlohmann::json(orientation_cov) : nlohmann::json(nullptr);
  j["rule"] = c.trial_orientations > 1
                  ? "B = B sigma0 / mean sigma over the orientations (experiments.md §f.6, [R]); then "
                    "1 + CoV_lab^2 = (1 + CoV_B^2)(1 + CoV_orientation^2) gives the bonds' m_B and "
                    "B0 = B Gamma(1 + 1/m) / Gamma(1 + 1/m_B) puts the batch's mean on the lab's"
                  : "B0 = B sigma0 / sigma (experiments.md §f.6, [R])";
  j["batch"] = {{"dir", "batch"}, {"count", c.count}, {"first_seed", c.first_seed}};
  if (batch.plan_only) {
    j["batch"]["planned"] = true;
    detail::writeAtomically(dir / "calibration.json", detail::jsonText(j));
    detail::refreshSetReport(dir, log, "calibrate-bonds");
    log << "calibrate-bonds: batch planned; after it ran: rocklab collect " << batch.out_dir.string()
        << " && rocklab weibull " << batch.out_dir.string() << "\n";
    return kExitOk;
  }
  if (batch_code == kExitInterrupted) return batch_code;
  const int fit_code = weibullCommand(batch.out_dir, "strength_MPa", log);
  if (fit_code == kExitOk) {
    std::ifstream in(batch.out_dir / "weibull.json");
    const nlohmann::json w = nlohmann::json::parse(in);
    j["batch"]["weibull"] = w;
    const double m = w["weibull_m"].get<double>(), s0 = w["weibull_sigma0_MPa"].get<double>();
    j["batch"]["sigma0_off_pct"] = percentOff(s0, c.target.sigma0_MPa);
    j["batch"]["m_off_pct"] = percentOff(m, c.target.modulus);
    log << "calibrate-bonds: batch sigma0 = " << s0 << " MPa (target " << c.target.sigma0_MPa << ", "
        << signedPercent(percentOff(s0, c.target.sigma0_MPa)) << "), m = " << m << " (target "
        << c.target.modulus << ", " << signedPercent(percentOff(m, c.target.modulus)) << "), mean "
        << w["mean_MPa"].get<double>() << " MPa";
    if (c.target.mean_MPa > 0) log << " (lab " << c.target.mean_MPa << ")";
    log << ", R^2 " << w["weibull_r2"].get<double>() << "\n";
  }
  detail::writeAtomically(dir / "calibration.json", detail::jsonText(j));
  detail::refreshSetReport(batch.out_dir, log, "calibrate-bonds");  // with the Weibull fit now
  detail::refreshSetReport(dir, log, "calibrate-bonds");
  log << "calibrate-bonds: " << (dir / "calibration.json").string() << "\n";
  if (batch_code != kExitOk) return batch_code;
  return fit_code;
}

}  // namespace rocklab::experiments
