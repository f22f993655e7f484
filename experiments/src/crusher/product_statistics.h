#pragma once
// What a crusher run's product says beyond its sieve curve (issue 21's results):
// the sizes P50 and P80 read off the product's own cumulative mass curve, the
// throughput, the residence time of each product ball in the chamber, and the
// mantle's power from the work its walls do on the balls.
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

namespace rocklab::experiments::crusher {

struct ProductBall {
  std::uint64_t id = 0;
  double time = 0, diameter = 0, mass = 0;  // s (discharge), m, kg
  double residence = 0;                     // s in the chamber (NaN: entry not seen)
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(ProductBall, id, time, diameter, mass, residence)

/// The size (m) that `fraction` (0-1) of the mass is finer than, on the product's
/// own cumulative curve: the balls sorted by diameter, the curve through (d_k,
/// mass fraction of the balls up to and including k) linear between points, and
/// the smallest diameter below its own fraction. Empty without balls.
std::optional<double> sizeAtPassing(std::span<const ProductBall> balls, double fraction);

/// sizeAtPassing in mm for results.json: null without balls.
nlohmann::json sizeAtPassingMm(std::span<const ProductBall> balls, double fraction);

/// Mass fraction of `balls` finer than each of `sieves_mm` (mm), as a sieve chart's
/// cumulative passing; 0 at every sieve without balls.
std::vector<double> massPassing(std::span<const ProductBall> balls, const std::vector<double>& sieves_mm);

/// When each ball entered the chamber (its centre first below the chamber's top);
/// a fragment keeps its parent's entry, so the residence of a product fragment
/// runs from when its feed ball entered, however often it broke on the way.
class ChamberEntries {
 public:
  explicit ChamberEntries(double top_height) : top_(top_height) {}
  /// Records the entry time of every ball below the top not seen before.
  void record(std::span<const std::uint64_t> ids, std::span<const double> heights, double time);
  /// A ball broke into `fragments`: they entered when it did (if it had).
  void inherit(std::uint64_t parent, std::span<const std::uint64_t> fragments);
  /// Seconds from entry to `time`; NaN when the entry was not seen.
  double residence(std::uint64_t id, double time) const;

 private:
  double top_;
  std::map<std::uint64_t, double> entered_;

 public:
  NLOHMANN_DEFINE_TYPE_INTRUSIVE(ChamberEntries, entered_)  // a restart's state (the top is the scene's)
};

/// A drive's power over consecutive intervals: each sample is the mean power of
/// the `span` seconds from `time` on (its work over span), so the energy is exact
/// when the samples cover the run. A series averaged over `bin` seconds is kept
/// for a plot.
class PowerMeter {
 public:
  explicit PowerMeter(double bin) : bin_(bin) {}
  void add(double time, double power, double span);
  double energy() const { return energy_; }  // J
  /// Time from the first sample with a non-zero power to the end of the last one's span (s); 0 without one.
  double loadedTime() const { return last_loaded_ > first_loaded_ ? last_loaded_ - first_loaded_ : 0.0; }
  /// results.json's crusher.power block; the series as (bin centre s, mean W).
  nlohmann::json report() const;
  const std::vector<std::pair<double, double>>& series() const { return series_; }

 private:
  double bin_;
  double energy_ = 0, first_loaded_ = 0, last_loaded_ = 0;
  std::uint64_t samples_ = 0;
  double bin_start_ = 0, bin_energy_ = 0, bin_span_ = 0;
  std::vector<std::pair<double, double>> series_;
  bool loaded_ = false;

 public:
  NLOHMANN_DEFINE_TYPE_INTRUSIVE(PowerMeter, energy_, first_loaded_, last_loaded_, samples_, bin_start_, bin_energy_,
                                 bin_span_, series_, loaded_)  // a restart's state (the bin is the scene's)
};

/// results.json's product statistics: p50_mm, p80_mm, throughput_tph (product
/// mass over the time from the first to the last discharge), residence_s (mean,
/// median, max over the product balls whose entry was seen).
nlohmann::json productStatistics(std::span<const ProductBall> product);

}  // namespace rocklab::experiments::crusher
