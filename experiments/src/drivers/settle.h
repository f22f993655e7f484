#pragma once
// The settle detector every depositing experiment shares (heap; the chute's
// deposition; the Zwick and crusher feeds next): a deposit is settled when no
// ball is faster than settle_speed, looked at on the driver's sample steps and
// not before settle_min_time; at settle_max_time it ends unsettled, and the
// report says so instead of hiding it.
#include <nlohmann/json.hpp>

#include "drivers/experiment.h"
#include "drivers/experiment_settings.h"

namespace rocklab::experiments {

class SettleDetector {
 public:
  explicit SettleDetector(const SettleSettings& s)
      : speed_limit_(s.speed), min_time_(s.min_time), max_time_(s.max_time) {}

  /// Call on a sample step: true once the deposit is over (settled, or out of time).
  /// Balls with skip[i] (when given) do not count: the chute's top plate deletes them.
  bool over(const sim::World& world, const std::vector<bool>& skip = {}) {
    speed_ = maxBallSpeed(world.particles(), skip);
    const double t = world.time();
    if (t < min_time_) return false;
    settled_ = speed_ < speed_limit_;
    return settled_ || t >= max_time_;
  }
  bool settled() const { return settled_; }
  /// m/s, the largest ball speed at the last sample.
  double maxSpeed() const { return speed_; }
  // A restart's state (the limits are the scene's).
  NLOHMANN_DEFINE_TYPE_INTRUSIVE(SettleDetector, settled_, speed_)

 private:
  double speed_limit_, min_time_, max_time_;  // m/s, s, s
  bool settled_ = false;
  double speed_ = 0.0;
};

}  // namespace rocklab::experiments
