#include "rocklab/geometry/structure_statistics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "parameter_check.h"
#include "rocklab/geometry/bond_pairs.h"

namespace rocklab::geometry {

namespace {
double ballVolume(double r) {
  return 4.0 / 3.0 * std::numbers::pi * r * r * r;
}
}  // namespace

Vec3 volumeCentroid(const std::vector<Sphere>& spheres) {
  Vec3 sum = Vec3::Zero();
  double weight = 0;
  for (const Sphere& s : spheres) {
    const double w = s.radius * s.radius * s.radius;
    sum += w * s.centre;
    weight += w;
  }
  return weight > 0 ? Vec3(sum / weight) : Vec3::Zero();
}

double lensVolume(const Sphere& a, const Sphere& b) {
  const double d = (a.centre - b.centre).norm();
  const double big = std::max(a.radius, b.radius), small = std::min(a.radius, b.radius);
  if (d >= big + small) return 0.0;
  if (d <= big - small) return ballVolume(small);  // one inside the other
  // Sum of the two spherical caps cut by the radical plane.
  const double h = big + small - d;
  return std::numbers::pi * h * h *
         (d * d + 2 * d * small - 3 * small * small + 2 * d * big + 6 * small * big -
          3 * big * big) /
         (12 * d);
}

StructureStatistics structureStatistics(const std::vector<Sphere>& spheres, double envelope_volume,
                                        double gap_tolerance) {
  detail::requireParameter(envelope_volume > 0 && std::isfinite(envelope_volume),
                           "structureStatistics", "envelope_volume", envelope_volume,
                           "must be > 0 (m^3)");
  StructureStatistics s;
  s.sphere_count = spheres.size();
  s.envelope_volume = envelope_volume;
  const std::vector<SpherePair> contacts = bondPairs(spheres, gap_tolerance);
  s.contact_count = contacts.size();
  for (const Sphere& b : spheres) s.solid_volume += ballVolume(b.radius);
  // Every overlapping pair is a contact (gap < 0 <= tolerance), so the contact list has them all.
  for (const auto& [i, j] : contacts) {
    const double overlap = -sphereGap(spheres[i], spheres[j]);
    if (!(overlap > 0)) continue;
    ++s.overlapping_pairs;
    s.solid_volume -= lensVolume(spheres[i], spheres[j]);
    s.max_overlap = std::max(s.max_overlap, overlap);
    s.max_overlap_fraction =
        std::max(s.max_overlap_fraction, overlap / std::min(spheres[i].radius, spheres[j].radius));
  }
  s.porosity = 1.0 - s.solid_volume / envelope_volume;
  s.coordination_number =
      spheres.empty() ? 0.0 : 2.0 * static_cast<double>(s.contact_count) / s.sphere_count;
  return s;
}

}  // namespace rocklab::geometry
