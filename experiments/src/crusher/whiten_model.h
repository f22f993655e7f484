#pragma once
// Whiten's classification-breakage model of a crusher (experiments.md §h.2):
// material entering the breakage zone, x, is the feed plus what breakage sends
// back (Eq 3-18: f + B C x = x); what is not selected leaves as product (Eq 3-19:
// x = C x + P), so P = (I - C)(I - B C)^-1 f (Eq 3-20).
//
// Size classes run coarse to fine, so B (the fraction of class j's broken mass
// that reports to class i) is lower triangular and I - B C is solved by forward
// substitution: no iteration, so nothing to cap, and a class that would hold its
// mass for ever (all of it selected, all of its broken mass back in itself: the
// iteration x <- f + B C x never ends) is refused by name. Mass is conserved to
// round-off when every column of B sums to 1 (the finest class, the pan, takes
// what is finer than the smallest sieve).
#include <span>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>

namespace rocklab::experiments::crusher {

/// Size classes from increasing sieve sizes s_0 < ... < s_{n-1} (m): n + 1 classes,
/// coarse to fine: [s_{n-1}, inf), [s_{n-2}, s_{n-1}), ..., [0, s_0) (the pan).
class SizeClasses {
 public:
  explicit SizeClasses(std::vector<double> sieves);
  std::size_t size() const { return sieves_.size() + 1; }
  /// The class of a particle of diameter d (m).
  std::size_t classOf(double d) const;
  /// A class's size for the classification function: the geometric mean of its
  /// bounds; the top class one half sieve ratio above its lower bound, the pan
  /// one half ratio below s_0 (the ratio of the two sieves nearest).
  double representative(std::size_t k) const;
  /// Lower bound (m) of class k (0 for the pan).
  double lower(std::size_t k) const;

 private:
  std::vector<double> sieves_;  // increasing
};

/// Eq 3-21 to 3-23: the fraction of particles of size s selected for breakage: 0
/// below k1, 1 above k2, 1 - ((s - k2) / (k1 - k2))^exponent between (the study
/// prints exponent 2; Whiten's original fits it, often about 2.3). Needs k1 < k2.
double whitenClassification(double s, double k1, double k2, double exponent);

/// The breakage matrix of a split that turns a particle of diameter d into pieces of
/// diameter ratio[k] d holding mass_fraction[k] of its mass (summing to 1): each
/// class's parent at its representative size.
Eigen::MatrixXd splitBreakageMatrix(const SizeClasses& classes, std::span<const double> ratio,
                                    std::span<const double> mass_fraction);

struct WhitenInputError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Eq 3-20. f: feed mass per class; c: selection per class (0-1); B: lower
/// triangular, non-negative, columns summing to at most 1. Returns P per class.
/// Throws WhitenInputError naming the class or entry that breaks these rules, or a
/// class with B_jj c_j = 1 (its mass never leaves).
Eigen::VectorXd whitenProduct(const Eigen::MatrixXd& B, const Eigen::VectorXd& c, const Eigen::VectorXd& f);

/// Cumulative mass fraction finer than each sieve of `classes` (increasing sieves),
/// from mass per class.
std::vector<double> passingOfClasses(const SizeClasses& classes, const Eigen::VectorXd& mass);

}  // namespace rocklab::experiments::crusher
