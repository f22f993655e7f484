#include "rocklab/geometry/bond_pairs.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "parameter_check.h"
#include "rocklab/geometry/sphere_hash_grid.h"

namespace rocklab::geometry {

double sphereGap(const Sphere& a, const Sphere& b) {
  return (a.centre - b.centre).norm() - a.radius - b.radius;
}

bool withinBondGap(const Sphere& a, const Sphere& b, double gap_tolerance) {
  return sphereGap(a, b) <= gap_tolerance * std::min(a.radius, b.radius);
}

std::vector<SpherePair> bondPairs(const std::vector<Sphere>& spheres, double gap_tolerance) {
  detail::requireParameter(gap_tolerance >= 0 && std::isfinite(gap_tolerance), "bondPairs",
                           "gap_tolerance", gap_tolerance,
                           "must be a finite number >= 0 (a fraction of the smaller radius)");
  double r_max = 0;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    detail::requireParameter(spheres[i].radius > 0, "bondPairs",
                             "radius of sphere " + std::to_string(i), spheres[i].radius,
                             "must be > 0");
    r_max = std::max(r_max, spheres[i].radius);
  }
  if (spheres.empty()) return {};
  // The farthest bonded partner is 2 r_max (1 + tolerance/2) away: one cell covers it.
  SphereHashGrid grid{r_max * (2.0 + gap_tolerance), {}};
  for (std::size_t i = 0; i < spheres.size(); ++i) grid.insert(spheres[i], i);
  std::vector<SpherePair> pairs;
  for (std::size_t i = 0; i < spheres.size(); ++i)
    grid.forEachNear(spheres[i].centre, [&](const SphereHashGrid::Entry& e) {
      if (e.id > i && withinBondGap(spheres[i], e.sphere, gap_tolerance))
        pairs.emplace_back(i, e.id);
    });
  std::sort(pairs.begin(), pairs.end());
  // Colliding hash keys can visit one cell twice.
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace rocklab::geometry
