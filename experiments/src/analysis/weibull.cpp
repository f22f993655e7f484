#include "weibull.h"

#include "sample_statistics.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rocklab::experiments {

namespace {

struct LineFit {
  double slope = 0.0, intercept = 0.0, r2 = 0.0;
};

LineFit leastSquares(const std::vector<double>& x, const std::vector<double>& y) {
  const auto n = static_cast<double>(x.size());
  double sx = 0, sy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
  }
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  LineFit f;
  f.slope = sxx > 0 ? sxy / sxx : 0.0;
  f.intercept = my - f.slope * mx;
  f.r2 = sxx > 0 && syy > 0 ? sxy * sxy / (sxx * syy) : 1.0;
  return f;
}

}  // namespace

WeibullFit fitWeibull(std::vector<double> strengths) {
  if (strengths.size() < 3) {
    std::ostringstream s;
    s << "Weibull fit: " << strengths.size() << " strengths given, at least 3 are needed";
    throw std::invalid_argument(s.str());
  }
  for (double v : strengths)
    if (!(v > 0) || !std::isfinite(v)) {
      std::ostringstream s;
      s << "Weibull fit: strength " << v << " Pa: every strength must be finite and > 0";
      throw std::invalid_argument(s.str());
    }
  std::sort(strengths.begin(), strengths.end());
  WeibullFit fit;
  fit.count = strengths.size();
  const auto n = static_cast<double>(fit.count);
  std::vector<double> x, y;
  for (std::size_t i = 0; i < fit.count; ++i) {
    const double ps = 1.0 - static_cast<double>(i + 1) / (n + 1.0);  // Eq 5-2
    fit.survival.push_back(ps);
    x.push_back(std::log(strengths[i]));
    y.push_back(std::log(std::log(1.0 / ps)));  // Eq 5-4
  }
  const LineFit line = leastSquares(x, y);
  fit.modulus = line.slope;
  fit.sigma0 = std::exp(-line.intercept / line.slope);  // y = m ln s - m ln s0 = 0
  fit.r2 = line.r2;
  const SampleStatistics stats = sampleStatistics(strengths);
  fit.mean = stats.mean;
  fit.stddev = stats.sd;
  fit.cov = stats.cov();
  fit.sorted = std::move(strengths);
  return fit;
}

double weibullMeanFactor(double modulus) { return std::tgamma(1.0 + 1.0 / modulus); }

double weibullCov(double modulus) {
  const double g1 = std::tgamma(1.0 + 1.0 / modulus), g2 = std::tgamma(1.0 + 2.0 / modulus);
  return std::sqrt(std::max(0.0, g2 / (g1 * g1) - 1.0));
}

double weibullModulusForCov(double cov) {
  if (!(cov > 0) || !std::isfinite(cov)) {
    std::ostringstream s;
    s << "Weibull modulus for a CoV of " << cov << ": the CoV must be finite and > 0";
    throw std::invalid_argument(s.str());
  }
  double lo = std::log(0.05), hi = std::log(1e4);  // CoV(0.05) ~ 1e10, CoV(1e4) ~ 1.3e-4
  for (int k = 0; k < 200 && hi - lo > 1e-12; ++k) {
    const double mid = 0.5 * (lo + hi);
    (weibullCov(std::exp(mid)) > cov ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

PowerLawFit fitPowerLaw(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size() || x.size() < 2)
    throw std::invalid_argument("power-law fit: needs at least 2 (x, y) pairs of equal count");
  std::vector<double> lx, ly;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!(x[i] > 0) || !(y[i] > 0))
      throw std::invalid_argument("power-law fit: every x and y must be > 0");
    lx.push_back(std::log(x[i]));
    ly.push_back(std::log(y[i]));
  }
  const LineFit line = leastSquares(lx, ly);
  return {std::exp(line.intercept), line.slope, line.r2};
}

double drawWeibull(double modulus, double sigma0, geometry::Rng& rng) {
  double u = rng.uniform();
  while (u <= 0.0) u = rng.uniform();  // (0, 1): ln 0 is not a strength
  return sigma0 * std::pow(-std::log(u), 1.0 / modulus);
}

}  // namespace rocklab::experiments
