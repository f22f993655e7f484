#include "crusher/product_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rocklab::experiments::crusher {

std::optional<double> sizeAtPassing(std::span<const ProductBall> balls, double fraction) {
  if (balls.empty()) return std::nullopt;
  std::vector<ProductBall> sorted(balls.begin(), balls.end());
  std::sort(sorted.begin(), sorted.end(), [](const ProductBall& a, const ProductBall& b) { return a.diameter < b.diameter; });
  double total = 0;
  for (const ProductBall& b : sorted) total += b.mass;
  double below = 0, previous_size = 0, previous_passing = 0;
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    below += sorted[k].mass;
    const double passing = below / total;
    if (passing >= fraction) {
      if (k == 0) return sorted[0].diameter;  // the finest ball alone holds the fraction
      const double f = (fraction - previous_passing) / (passing - previous_passing);
      return previous_size + f * (sorted[k].diameter - previous_size);
    }
    previous_size = sorted[k].diameter;
    previous_passing = passing;
  }
  return sorted.back().diameter;  // fraction 1 up to round-off
}

std::vector<double> massPassing(std::span<const ProductBall> balls, const std::vector<double>& sieves_mm) {
  double total = 0;
  for (const ProductBall& b : balls) total += b.mass;
  std::vector<double> passing;
  for (const double sieve : sieves_mm) {
    double finer = 0;
    for (const ProductBall& b : balls)
      if (b.diameter * 1e3 < sieve) finer += b.mass;
    passing.push_back(total > 0 ? finer / total : 0.0);
  }
  return passing;
}

void ChamberEntries::record(std::span<const std::uint64_t> ids, std::span<const double> heights, double time) {
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (heights[i] < top_) entered_.try_emplace(ids[i], time);
}

void ChamberEntries::inherit(std::uint64_t parent, std::span<const std::uint64_t> fragments) {
  const auto at = entered_.find(parent);
  if (at == entered_.end()) return;
  const double time = at->second;
  for (const std::uint64_t f : fragments) entered_[f] = time;
}

double ChamberEntries::residence(std::uint64_t id, double time) const {
  const auto at = entered_.find(id);
  return at == entered_.end() ? std::numeric_limits<double>::quiet_NaN() : time - at->second;
}

void PowerMeter::add(double time, double power, double span) {
  energy_ += power * span;
  ++samples_;
  if (power != 0) {
    if (!loaded_) first_loaded_ = time;
    loaded_ = true;
    last_loaded_ = time + span;
  }
  if (bin_span_ == 0) bin_start_ = time;
  bin_energy_ += power * span;
  bin_span_ += span;
  if (time + span >= bin_start_ + bin_ * (1 - 1e-9)) {  // the bin is full (up to round-off in the times)
    series_.emplace_back(bin_start_ + 0.5 * bin_span_, bin_energy_ / bin_span_);
    bin_energy_ = bin_span_ = 0;
  }
}

nlohmann::json PowerMeter::report() const {
  const double loaded = loadedTime();
  return {{"energy_J", energy_},
          {"loaded_time_s", loaded},
          {"power_W", loaded > 0 ? nlohmann::json(energy_ / loaded) : nlohmann::json(nullptr)},
          {"samples", samples_},
          {"method",
           "energy_J: the work the moving walls (mantle and cap) did on the balls, every step's wall-contact force "
           "(dashpots included) x the wall's velocity at the contact; power_W = energy_J / loaded_time_s, the time "
           "from the first to the end of the last sample interval in which they did work"}};
}

nlohmann::json sizeAtPassingMm(std::span<const ProductBall> balls, double fraction) {
  const std::optional<double> d = sizeAtPassing(balls, fraction);
  return d ? nlohmann::json(*d * 1e3) : nlohmann::json(nullptr);
}

nlohmann::json productStatistics(std::span<const ProductBall> product) {
  nlohmann::json s;
  s["p50_mm"] = sizeAtPassingMm(product, 0.5);
  s["p80_mm"] = sizeAtPassingMm(product, 0.8);
  double mass = 0, first = std::numeric_limits<double>::infinity(), last = -first;
  std::vector<double> residence;
  for (const ProductBall& b : product) {
    mass += b.mass;
    first = std::min(first, b.time);
    last = std::max(last, b.time);
    if (std::isfinite(b.residence)) residence.push_back(b.residence);
  }
  s["throughput_tph"] = last > first ? nlohmann::json(mass * 1e-3 / ((last - first) / 3600.0)) : nlohmann::json(nullptr);
  nlohmann::json r;
  r["balls"] = residence.size();
  if (!residence.empty()) {
    std::sort(residence.begin(), residence.end());
    double sum = 0;
    for (const double t : residence) sum += t;
    const std::size_t n = residence.size();
    r["mean"] = sum / static_cast<double>(n);
    r["median"] = n % 2 ? residence[n / 2] : 0.5 * (residence[n / 2 - 1] + residence[n / 2]);
    r["max"] = residence.back();
  }
  s["residence_s"] = r;
  return s;
}

}  // namespace rocklab::experiments::crusher
