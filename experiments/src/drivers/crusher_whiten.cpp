#include "drivers/crusher_whiten.h"

#include <algorithm>
#include <cmath>

#include "crusher/breakage_model.h"
#include "crusher/whiten_model.h"

namespace rocklab::experiments {

namespace {

using crusher::SizeClasses;

std::vector<double> toVector(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

nlohmann::json passingJson(const std::vector<double>& sieves_mm, const std::vector<double>& passing) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < sieves_mm.size(); ++k) out.push_back({{"size_mm", sieves_mm[k]}, {"passing", passing[k]}});
  return out;
}

Eigen::VectorXd massPerClass(const SizeClasses& classes, const std::vector<crusher::ProductBall>& balls) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(classes.size()));
  for (const crusher::ProductBall& b : balls) m[static_cast<Eigen::Index>(classes.classOf(b.diameter))] += b.mass;
  return m;
}

std::vector<double> metres(const std::vector<double>& sieves_mm) {
  std::vector<double> sieves;
  for (const double s : sieves_mm) sieves.push_back(s * 1e-3);
  return sieves;
}

}  // namespace

WhitenPrediction whitenFromParameters(const std::vector<double>& sieves_mm, const Eigen::VectorXd& feed, double k1,
                                      double k2, double exponent, crusher::SplitMode mode) {
  const SizeClasses classes(metres(sieves_mm));
  const Eigen::Index n = static_cast<Eigen::Index>(classes.size());
  Eigen::VectorXd c(n);
  for (Eigen::Index k = 0; k < n; ++k)
    c[k] = crusher::whitenClassification(classes.representative(static_cast<std::size_t>(k)), k1, k2, exponent);
  std::vector<double> ratio, fractions = crusher::massFractions(mode);
  for (const double f : fractions) ratio.push_back(std::cbrt(f));
  const Eigen::VectorXd product =
      crusher::whitenProduct(crusher::splitBreakageMatrix(classes, ratio, fractions), c, feed);
  return {toVector(c), crusher::passingOfClasses(classes, product),
          feed.sum() > 0 ? (product.sum() - feed.sum()) / feed.sum() : 0.0};
}

nlohmann::json whitenReport(const WhitenSettings& settings, const WhitenInputs& in, std::vector<double>& model_passing) {
  const SizeClasses classes(metres(in.sieves_mm));
  const Eigen::Index n = static_cast<Eigen::Index>(classes.size());
  const Eigen::VectorXd feed = massPerClass(classes, *in.feed);
  nlohmann::json r;
  nlohmann::json lower = nlohmann::json::array();
  for (std::size_t k = 0; k < classes.size(); ++k) lower.push_back(classes.lower(k) * 1e3);
  r["class_lower_mm"] = lower;  // coarse to fine; the last is the pan
  r["method"] = "Eq 3-20, P = (I - C)(I - B C)^-1 f over the sieve classes (coarse to fine), solved by forward "
                "substitution (no iteration)";

  // From parameters.
  const double k1 = settings.k1 > 0 ? settings.k1 : in.chamber_css.value_or(0.0);
  const double k2 = settings.k2 > 0 ? settings.k2 : in.chamber_oss.value_or(0.0);
  nlohmann::json p;
  model_passing.clear();
  if (k1 > 0 && k2 > k1) {
    const WhitenPrediction w = whitenFromParameters(in.sieves_mm, feed, k1, k2, settings.exponent, in.mode);
    model_passing = w.passing;
    p = {{"k1_mm", k1 * 1e3},
         {"k2_mm", k2 * 1e3},
         {"exponent", settings.exponent},
         {"split", crusher::modeName(in.mode)},
         {"selection", w.selection},
         {"passing", passingJson(in.sieves_mm, model_passing)},
         {"mass_balance_relative", w.mass_balance_relative}};
  } else {
    p = {{"skipped", "needs 0 < k1 < k2: set experiment.whiten_k1_mm and whiten_k2_mm, or run a scene with a [crusher]"}};
  }
  r["from_parameters"] = p;

  // From the run's breakage events.
  if (in.events && !in.events->empty()) {
    Eigen::VectorXd broken = Eigen::VectorXd::Zero(n), created = Eigen::VectorXd::Zero(n);
    Eigen::MatrixXd to = Eigen::MatrixXd::Zero(n, n);  // mass from broken class j into class i
    for (const BreakageEvent& e : *in.events) {
      const Eigen::Index j = static_cast<Eigen::Index>(classes.classOf(e.diameter));
      broken[j] += e.mass;
      for (std::size_t k = 0; k < e.fragment_masses.size(); ++k) {
        const Eigen::Index i = static_cast<Eigen::Index>(classes.classOf(e.fragment_diameters[k]));
        to(i, j) += e.fragment_masses[k];
        created[i] += e.fragment_masses[k];
      }
    }
    const Eigen::VectorXd entered = feed + created;
    Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index j = 0; j < n; ++j) {
      if (entered[j] > 0) c[j] = std::min(1.0, broken[j] / entered[j]);
      if (broken[j] > 0) B.col(j) = to.col(j) / broken[j];
    }
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index i = 0; i < n; ++i) rows.push_back(toVector(B.row(i).transpose()));
    nlohmann::json m = {{"selection", toVector(c)}, {"breakage_matrix", rows}};
    try {
      const std::vector<double> passing = crusher::passingOfClasses(classes, crusher::whitenProduct(B, c, feed));
      const std::vector<double> run = crusher::passingOfClasses(classes, massPerClass(classes, *in.product));
      double largest = 0;
      for (std::size_t k = 0; k < passing.size(); ++k) largest = std::max(largest, std::abs(passing[k] - run[k]));
      m["passing"] = passingJson(in.sieves_mm, passing);
      m["largest_difference_from_product"] = largest;
      m["note"] = "the run's product plus what is still in the chamber: equal to the product when the chamber is empty";
    } catch (const crusher::WhitenInputError& e) {
      m["error"] = e.what();  // a class that traps its mass: reported, the run's results stand
    }
    r["from_run"] = m;
  }
  return r;
}

}  // namespace rocklab::experiments
