#include "agglomerate/locked_in_stress.h"

#include <cmath>
#include <stdexcept>

#include "rocklab/sim/timestep.h"  // hertzCoefficient (Eq 2-22)

namespace rocklab::experiments::agglomerate {

LockedInStress lockedInStress(const std::vector<geometry::Sphere>& spheres,
                              const std::vector<geometry::SpherePair>& pairs, double shear_modulus,
                              double poisson, double volume) {
  if (!(volume > 0)) throw std::invalid_argument("locked-in stress: volume must be > 0");
  if (!(shear_modulus > 0))
    throw std::invalid_argument("locked-in stress: shear_modulus must be > 0");
  LockedInStress s;
  for (const auto& [a, b] : pairs) {
    const geometry::Sphere &sa = spheres[a], &sb = spheres[b];
    const geometry::Vec3 branch = sb.centre - sa.centre;
    const double overlap = -geometry::sphereGap(sa, sb);
    if (overlap <= 0) continue;
    const double r_tilde = 2.0 * sa.radius * sb.radius / (sa.radius + sb.radius);  // Eq 2-24
    const double force = sim::hertzCoefficient(shear_modulus, poisson, r_tilde) * overlap *
                         std::sqrt(overlap);  // Eq 2-22 with Eq 2-2
    // The force on b pushes it away from a: along the branch, so l F is positive.
    s.tensor += (force / branch.norm()) * branch * branch.transpose();
  }
  s.tensor /= volume;
  s.mean = s.tensor.trace() / 3.0;
  return s;
}

}  // namespace rocklab::experiments::agglomerate
