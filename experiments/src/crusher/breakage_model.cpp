#include "crusher/breakage_model.h"

#include <cmath>
#include <sstream>

#include "rocklab/geometry/mix64.h"

namespace rocklab::experiments::crusher {

double StrengthLaw::scale(double diameter) const {
  return q_ref * std::pow(diameter / d_ref, size_exponent);
}

double StrengthLaw::strength(double diameter, double u) const {
  return scale(diameter) * std::pow(-std::log(u), 1.0 / weibull_modulus);
}

double uniformFromId(std::uint64_t seed, std::uint64_t id) {
  // Two rounds: the seed's hash keys the id's, so neighbouring seeds and ids give
  // unrelated draws. 53 bits, centred in their cell: never 0 or 1 (-ln U is finite).
  auto splitmix64 = [](std::uint64_t x) { return geometry::mix64(x + geometry::kSplitmixGamma); };
  const std::uint64_t h = splitmix64(splitmix64(seed) ^ id);
  return (static_cast<double>(h >> 11) + 0.5) * 0x1.0p-53;
}

std::vector<double> massFractions(SplitMode mode) {
  return mode == SplitMode::Triple ? std::vector<double>{0.6, 0.3, 0.1} : std::vector<double>{0.5, 0.5};
}

std::vector<double> defaultOffsets(SplitMode mode) {
  if (mode == SplitMode::Triple) return {-(1.0 - std::cbrt(0.6)), 1.0 - std::cbrt(0.3), 0.0};
  const double half = 1.0 - std::cbrt(0.5);
  return {-half, half};
}

std::string offsetsProblem(SplitMode mode, const std::vector<double>& offsets) {
  const std::vector<double> fractions = massFractions(mode);
  std::ostringstream s;
  if (offsets.size() != fractions.size()) {
    s << "needs " << fractions.size() << " offsets (one per fragment, in parent radii), got " << offsets.size();
    return s.str();
  }
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    const double reach = std::abs(offsets[k]) + std::cbrt(fractions[k]);
    if (!std::isfinite(offsets[k]) || reach > 1.0 + 1e-9) {
      s << "offset " << k << " = " << offsets[k] << " puts the " << fractions[k] * 100
        << " % fragment (radius " << std::cbrt(fractions[k]) << " R) outside the parent: |offset| must be at most "
        << 1.0 - std::cbrt(fractions[k]);
      return s.str();
    }
  }
  return {};
}

std::vector<FragmentBall> splitBall(const geometry::Vec3& centre, double radius, double mass,
                                    const geometry::Vec3& direction, SplitMode mode,
                                    const std::vector<double>& offsets) {
  const std::vector<double> fractions = massFractions(mode);
  std::vector<FragmentBall> out(fractions.size());
  double left = mass;
  for (std::size_t k = 0; k < fractions.size(); ++k) {
    FragmentBall& f = out[k];
    f.mass = k + 1 < fractions.size() ? fractions[k] * mass : left;
    left -= f.mass;
    f.radius = radius * std::cbrt(f.mass / mass);
    f.position = centre + offsets[k] * radius * direction;
  }
  return out;
}

}  // namespace rocklab::experiments::crusher
