#include "crusher/whiten_model.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rocklab::experiments::crusher {

SizeClasses::SizeClasses(std::vector<double> sieves) : sieves_(std::move(sieves)) {
  if (sieves_.size() < 2 || !std::is_sorted(sieves_.begin(), sieves_.end()) ||
      std::adjacent_find(sieves_.begin(), sieves_.end()) != sieves_.end() || !(sieves_.front() > 0))
    throw WhitenInputError("size classes need at least two sieve sizes, positive and increasing");
}

std::size_t SizeClasses::classOf(double d) const {
  // Sieves passed: how many sieves are larger than d; class 0 is the top.
  const std::size_t finer_than = static_cast<std::size_t>(sieves_.end() - std::upper_bound(sieves_.begin(), sieves_.end(), d));
  return finer_than;
}

double SizeClasses::lower(std::size_t k) const {
  const std::size_t n = sieves_.size();
  return k >= n ? 0.0 : sieves_[n - 1 - k];
}

double SizeClasses::representative(std::size_t k) const {
  const std::size_t n = sieves_.size();
  if (k == 0) return sieves_[n - 1] * std::sqrt(sieves_[n - 1] / sieves_[n - 2]);
  if (k >= n) return sieves_[0] / std::sqrt(sieves_[1] / sieves_[0]);
  return std::sqrt(sieves_[n - 1 - k] * sieves_[n - k]);
}

double whitenClassification(double s, double k1, double k2, double exponent) {
  if (!(k1 < k2)) throw WhitenInputError("Whiten's classification needs k1 < k2");
  if (s <= k1) return 0.0;  // Eq 3-21
  if (s >= k2) return 1.0;  // Eq 3-23
  return 1.0 - std::pow((s - k2) / (k1 - k2), exponent);  // Eq 3-22
}

Eigen::MatrixXd splitBreakageMatrix(const SizeClasses& classes, std::span<const double> ratio,
                                    std::span<const double> mass_fraction) {
  const std::size_t n = classes.size();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  for (std::size_t j = 0; j < n; ++j) {
    const double d = classes.representative(j);
    for (std::size_t k = 0; k < ratio.size(); ++k) {
      // A piece never lands coarser than its parent's class (ratio < 1).
      const std::size_t i = std::max(j, classes.classOf(ratio[k] * d));
      B(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) += mass_fraction[k];
    }
  }
  return B;
}

Eigen::VectorXd whitenProduct(const Eigen::MatrixXd& B, const Eigen::VectorXd& c, const Eigen::VectorXd& f) {
  const Eigen::Index n = f.size();
  if (B.rows() != n || B.cols() != n || c.size() != n) {
    std::ostringstream s;
    s << "Whiten's model: B must be " << n << " x " << n << " and c of " << n << " classes (the feed's), got B "
      << B.rows() << " x " << B.cols() << " and c of " << c.size();
    throw WhitenInputError(s.str());
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    auto fail = [&](const std::string& what) {
      std::ostringstream s;
      s << "Whiten's model, class " << j << ": " << what;
      throw WhitenInputError(s.str());
    };
    if (!(f[j] >= 0) || !std::isfinite(f[j])) fail("the feed must be a finite mass >= 0");
    if (!(c[j] >= 0 && c[j] <= 1)) fail("the selection c must be within 0 and 1");
    double column = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!(B(i, j) >= 0) || !std::isfinite(B(i, j))) fail("B's entries must be finite and >= 0");
      if (i < j && B(i, j) > 0) fail("B must be lower triangular (broken mass goes to finer classes only)");
      column += B(i, j);
    }
    if (column > 1 + 1e-12) fail("B's column sums to more than 1 (breakage would create mass)");
    if (1 - B(j, j) * c[j] <= 1e-12)
      fail("all of it is selected and all of its broken mass stays in it: its mass never leaves (B_jj c_j = 1)");
  }
  // (I - B C) x = f, forward substitution (lower triangular).
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    double rhs = f[i];
    for (Eigen::Index j = 0; j < i; ++j) rhs += B(i, j) * c[j] * x[j];
    x[i] = rhs / (1 - B(i, i) * c[i]);
  }
  return (Eigen::VectorXd::Ones(n) - c).cwiseProduct(x);  // Eq 3-19: P = (I - C) x
}

std::vector<double> passingOfClasses(const SizeClasses& classes, const Eigen::VectorXd& mass) {
  const double total = mass.sum();
  std::vector<double> passing;
  // Finer than sieve s_m: the classes below it, i.e. classes n - m .. n (pan last).
  const std::size_t n = classes.size() - 1;  // sieves
  for (std::size_t m = 0; m < n; ++m) {
    double finer = 0;
    for (std::size_t k = n - m; k <= n; ++k) finer += mass[static_cast<Eigen::Index>(k)];
    passing.push_back(total > 0 ? finer / total : 0.0);
  }
  return passing;
}

}  // namespace rocklab::experiments::crusher
