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

#include "analysis/weibull_report.h"
#include "common/atomic_file.h"
#include "common/json_text.h"
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

  // Trials: B_{k+1} = B_k sigma0 / sigma_k (§f.6 step 4, [R]).
  nlohmann::json trials = nlohmann::json::array();
  std::vector<std::vector<std::string>> rows;
  double bond = c.trial_strength_Pa, calibrated = NAN;
  for (int k = 0; k < c.max_trials; ++k) {
    SweepOptions o = c.runs;
    for (const std::string& s : constantStrength(bond)) o.overrides.push_back(s);
    detail::Variant v;
    detail::runVariant(o, dir / ("trial-" + std::to_string(k + 1)), v, log);
    if (v.code == kExitInterrupted) return kExitInterrupted;
    const double sigma = detail::number(detail::lookup(v.results, "strength_MPa")) * 1e6;
    const double wall = detail::number(detail::lookup(v.results, "wall_time_s.total"));
    if (v.code != kExitOk || !(sigma > 0)) {
      log << "calibrate-bonds: trial " << k + 1 << " (B = " << bond * 1e-6 << " MPa) failed: exit " << v.code
          << "; see " << (dir / ("trial-" + std::to_string(k + 1)) / "run.log").string() << "\n";
      return kExitRunsFailed;
    }
    const double next = bond * target_pa / sigma;
    log << "calibrate-bonds: trial " << k + 1 << ": B = " << bond * 1e-6 << " MPa -> sigma = " << sigma * 1e-6
        << " MPa (" << signedPercent(percentOff(sigma, target_pa)) << " off sigma0), " << wall
        << " s; B0 = B sigma0 / sigma = " << next * 1e-6
        << " MPa\n";
    trials.push_back({{"bond_strength_Pa", bond},
                      {"strength_MPa", sigma * 1e-6},
                      {"off_target_pct", percentOff(sigma, target_pa)},
                      {"next_bond_strength_Pa", next},
                      {"wall_time_s", wall}});
    rows.push_back({std::to_string(k + 1), detail::cell(bond * 1e-6), detail::cell(sigma * 1e-6),
                    detail::cell(percentOff(sigma, target_pa)), detail::cell(next * 1e-6), detail::cell(wall)});
    calibrated = next;
    if (std::abs(percentOff(sigma, target_pa)) <= c.tolerance_pct) {
      calibrated = bond;  // this trial is on target: keep its B
      break;
    }
    bond = next;
  }
  detail::writeTable({"trial", "bond_strength_MPa", "strength_MPa", "off_sigma0_pct", "B0_MPa", "wall_s"}, rows,
                     dir / "calibration.csv", log);

  // The batch: one Weibull-drawn strength per agglomerate, modulus m, 37 % value B0.
  SweepOptions batch = c.runs;
  batch.out_dir = dir / "batch";
  for (const std::string& s : constantStrength(calibrated)) batch.overrides.push_back(s);
  batch.overrides.push_back("bonds.strength_distribution = \"weibull_per_agglomerate\"");
  batch.overrides.push_back("bonds.weibull_modulus = " + detail::cell(c.target.modulus));
  std::vector<std::string> seeds;
  for (int k = 0; k < c.count; ++k) seeds.push_back(std::to_string(c.first_seed + k));
  batch.vary = {{"scene.seed", seeds}};
  batch.metrics = {"strength_MPa", "peak_force_N", "zwick.platen_gap_at_peak_m", "bonds_broken",
                   "zwick.agglomerate_bond_strength_Pa", "wall_time_s.total"};
  log << "calibrate-bonds: batch of " << c.count << " with B0 = " << calibrated * 1e-6 << " MPa, m = "
      << c.target.modulus << " into " << batch.out_dir.string() << "\n";
  const int batch_code = runSweep(batch, log);
  nlohmann::json j;
  j["target"] = {{"fraction_mm", c.target.name},
                 {"sigma0_MPa", c.target.sigma0_MPa},
                 {"mean_MPa", c.target.mean_MPa},
                 {"r2", c.target.r2},
                 {"weibull_m", c.target.modulus},
                 {"source", "Table 5.1 (experiments.md §e)"}};
  j["trials"] = trials;
  j["calibrated_bond_strength_Pa"] = calibrated;
  j["rule"] = "B0 = B sigma0 / sigma (experiments.md §f.6, [R])";
  j["batch"] = {{"dir", "batch"}, {"count", c.count}, {"first_seed", c.first_seed}};
  if (batch.plan_only) {
    j["batch"]["planned"] = true;
    detail::writeAtomically(dir / "calibration.json", detail::jsonText(j));
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
  log << "calibrate-bonds: " << (dir / "calibration.json").string() << "\n";
  if (batch_code != kExitOk) return batch_code;
  return fit_code;
}

}  // namespace rocklab::experiments
