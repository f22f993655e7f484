#pragma once
// Strength statistics of crushing tests (experiments.md §e): the mean-rank
// Weibull fit of Eq 5-2..5-4 and the size-effect power law of Eq 5-5.
#include <cstddef>
#include <vector>

#include "rocklab/geometry/packing.h"  // geometry::Rng

namespace rocklab::experiments {

struct WeibullFit {
  std::size_t count = 0;
  double modulus = 0.0;          // -   m, slope of ln ln(1/P_s) against ln sigma (Eq 5-4)
  double sigma0 = 0.0;           // Pa  37 % strength: where the fitted line crosses zero (Eq 5-3)
  double r2 = 0.0;               // -   of the linearised fit
  double mean = 0.0;             // Pa
  double stddev = 0.0;           // Pa  sample standard deviation (n - 1)
  double cov = 0.0;              // -   stddev / mean
  std::vector<double> sorted;    // Pa, ascending (rank i = index + 1)
  std::vector<double> survival;  // mean-rank P_s = 1 - i / (N + 1) of each (Eq 5-2)
};

/// Fits the strengths of one batch; needs at least 3 positive values
/// (throws std::invalid_argument naming the problem otherwise).
WeibullFit fitWeibull(std::vector<double> strengths);

/// y = a x^b by least squares on ln y against ln x (Eq 5-5: sigma_av = a d^b).
struct PowerLawFit {
  double a = 0.0, b = 0.0, r2 = 0.0;
};
PowerLawFit fitPowerLaw(const std::vector<double>& x, const std::vector<double>& y);

/// Moments of a Weibull distribution of modulus m (independent of sigma0):
/// mean = sigma0 Gamma(1 + 1/m), CoV = sqrt(Gamma(1 + 2/m) / Gamma(1 + 1/m)^2 - 1).
double weibullMeanFactor(double modulus);
double weibullCov(double modulus);
/// The modulus whose CoV is `cov` (> 0): CoV falls monotonically with m, so bisection
/// on ln m over [0.05, 1e4]; throws std::invalid_argument for cov <= 0 or not finite.
double weibullModulusForCov(double cov);

/// A Weibull draw of modulus m and 37 % value sigma0: sigma0 (-ln U)^(1/m),
/// U uniform in (0, 1) (experiments.md §f.6 [X]).
double drawWeibull(double modulus, double sigma0, geometry::Rng& rng);

}  // namespace rocklab::experiments
