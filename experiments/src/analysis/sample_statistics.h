#pragma once
// Mean and scatter of a set of samples (seeds, random samples, trials): the one
// definition behind every table that reports "mean ± sd" (studies, samples, strength
// groups, bond calibration, Weibull fits).
#include <cstddef>
#include <limits>
#include <span>

namespace rocklab::experiments {

struct SampleStatistics {
  std::size_t n = 0;
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  double mean = kNone;  // NaN for no sample
  double sd = kNone;    // sample standard deviation (divisor n - 1); NaN below two samples
  double min = kNone, max = kNone;
  double cov() const { return sd / mean; }  // coefficient of variation
};

/// Sum divided by n for the mean, then the corrected sum of squares about it.
SampleStatistics sampleStatistics(std::span<const double> values);

}  // namespace rocklab::experiments
