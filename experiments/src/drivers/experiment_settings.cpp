#include "drivers/experiment_settings.h"

#include <string>

namespace rocklab::experiments {

void readSettleSettings(TableReader& t, SettleSettings& s) {
  const Range positive = Range::positive();
  s.speed = t.number("settle_speed", s.speed, positive);
  s.min_time = t.number("settle_min_time", s.min_time, Range::nonNegative());
  s.max_time = t.number("settle_max_time", s.max_time, positive);
}

int readCalibrationPhotos(TableReader& t, int fallback) {
  const auto photos =
      static_cast<int>(t.integer("calibration_photos", fallback, Range::closed(0, 11)));
  if (photos > 0 && photos < 3)
    t.fail("calibration_photos",
           "needs 0 (exact camera) or 3 to 11 photos (got " + std::to_string(photos) + ")");
  return photos;
}

}  // namespace rocklab::experiments
