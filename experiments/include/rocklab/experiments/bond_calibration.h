#pragma once
// Calibration of bond strengths against a laboratory size fraction
// (experiments.md §f.6): crush one agglomerate with a trial bond strength B,
// scale it to the lab's 37 % strength, B0 = B sigma0 / sigma ([R]: the text
// prints the ratio upside down), and repeat until a trial lands within the
// tolerance; then crush a batch of agglomerates whose bond strengths are drawn
// from a Weibull distribution of the lab's modulus m and 37 % value B0 (one
// value per agglomerate, normal = shear strength, §f.6 [I]) and compare the
// batch's Weibull fit (Eq 5-2..5-4) with the lab's. With trial_orientations > 1
// each trial is the mean over several orientations and the bonds' modulus is
// corrected for the orientations' own spread (rocklab's extension, docs/crushing.md).
#include <iosfwd>
#include <optional>
#include <string>

#include "rocklab/experiments/sweep.h"

namespace rocklab::experiments {

/// One fraction of the lab's crushing results (Table 5.1), the calibration target.
struct LabFraction {
  std::string name;        // "40-60" (mm)
  double sigma0_MPa = 0;   // 37 % strength
  double mean_MPa = 0;     // mean strength
  double r2 = 0;           // of the lab's Weibull fit
  double modulus = 0;      // m
};

/// Table 5.1 by name: "14-28", "30-37.5" or "40-60"; nullopt for another name.
std::optional<LabFraction> tableFiveOneFraction(const std::string& name);
/// The names tableFiveOneFraction knows, for help and errors.
std::string tableFiveOneNames();

struct BondCalibrationOptions {
  SweepOptions runs;                // scene, --set, --out, --jobs, threads (no --vary)
  LabFraction target;               // sigma0 and m at least
  double trial_strength_Pa = 60e6;  // B of the first trial (Table 5.2's 60 MPa)
  int max_trials = 3;               // trials at most (each scales B by sigma0 / sigma)
  double tolerance_pct = 2.0;       // a trial within this of sigma0 ends the trials
  int count = 30;                   // agglomerates of the batch (the study: 30)
  int first_seed = 1;               // scene.seed of the batch's first run (then +1, ...)
  // Orientations per trial (scene.seed = first_seed + count, +1, ...: none of the batch's):
  // 1 is the study's rule; K > 1 averages the trial over K orientations and takes their
  // spread out of the bonds' (bond_calibration.cpp, bondSpreadFor).
  int trial_orientations = 1;
};

/// Runs the trials (printing each), then the batch (a sweep over scene.seed in
/// DIR/batch, with --jobs or --plan as every sweep), then its Weibull analysis;
/// writes DIR/calibration.json and DIR/calibration.csv (the trials). Returns an
/// ExitCode: 2 on bad input before any run, 4 when a run failed, 130 interrupted.
int runBondCalibration(const BondCalibrationOptions& options, std::ostream& log);

}  // namespace rocklab::experiments
