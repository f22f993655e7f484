#pragma once
// Whiten's classification-breakage model (crusher/whiten_model.h) beside a crusher
// run's product, two ways:
//   - from parameters: k1 and k2 of Eq 3-21 to 3-23 (default: the built chamber's
//     closed-side gap and open-side setting, §h.2's "k1 ~ CSS, k2 ~ OSS"), the
//     study's exponent 2, and B from the run's split mode (each class's parent at
//     its representative size): the empirical model's product curve for the
//     run's feed, a prediction to set beside the DEM's;
//   - from the run: the selection c and the breakage matrix B measured on its
//     breakage events (c_j = mass of class j that broke / mass that entered class
//     j, as feed or as fragments; B_ij = fraction of class j's broken mass whose
//     fragments fell in class i). Eq 3-20 with these gives back the run's product
//     plus what is still in the chamber, exactly: a mass-balance check of the run
//     and of the bookkeeping, not a prediction.
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "crusher/product_statistics.h"
#include "drivers/crusher_breakage.h"

namespace rocklab::experiments {

struct WhitenSettings {
  double k1 = 0, k2 = 0;   // m; 0: the chamber's closed-side gap and open-side setting
  double exponent = 2.0;   // Eq 3-22 as the study prints it (Whiten's fits are often ~2.3)
};

struct WhitenInputs {
  std::vector<double> sieves_mm;
  const std::vector<crusher::ProductBall>* feed = nullptr;
  const std::vector<crusher::ProductBall>* product = nullptr;
  const std::vector<BreakageEvent>* events = nullptr;  // null: the run had no breakage
  crusher::SplitMode mode = crusher::SplitMode::Triple;
  std::optional<double> chamber_css, chamber_oss;  // m, of the built chamber when the scene has one
};

/// Whiten's model from parameters for a feed given as mass per size class of
/// `sieves_mm` (crusher::SizeClasses, coarse to fine): k1, k2 in m, B from `mode`.
struct WhitenPrediction {
  std::vector<double> selection;  // c per class
  std::vector<double> passing;    // the product's mass fraction finer than each sieve
  double mass_balance_relative = 0;
};
WhitenPrediction whitenFromParameters(const std::vector<double>& sieves_mm, const Eigen::VectorXd& feed_per_class,
                                      double k1, double k2, double exponent, crusher::SplitMode mode);

/// results.json's crusher.whiten; `model_passing` gets the from-parameters curve
/// (mass fraction finer than each sieve; empty when k1, k2 are unknown).
nlohmann::json whitenReport(const WhitenSettings& settings, const WhitenInputs& in, std::vector<double>& model_passing);

}  // namespace rocklab::experiments
