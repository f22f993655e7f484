#pragma once
// Locked-in stress of an agglomerate: the mean stress its initial overlaps would
// carry once the spheres are DEM balls with the Hertz law (dem-models.md §4.2),
// by the average-stress definition of dem-models.md §11 applied to the assembly:
//   sigma_ij = (1/V) sum over overlapping pairs of l_i F_j,
// l the branch vector from one centre to the other, F the Hertz normal force
// c delta^(3/2) (Eq 2-22, Eq 2-24..2-26 pair properties) on the second sphere,
// compression positive. V is the agglomerate's envelope (bounding sphere, mesh).
#include <vector>

#include "rocklab/geometry/bond_pairs.h"
#include "rocklab/geometry/packing.h"

namespace rocklab::experiments::agglomerate {

struct LockedInStress {
  geometry::Mat3 tensor = geometry::Mat3::Zero();  // Pa, compression positive (symmetric)
  double mean = 0.0;                               // Pa, trace / 3
};

/// Over `pairs` (those with a negative gap contribute); the same G and nu for every
/// sphere. Throws std::invalid_argument for volume <= 0 or shear_modulus <= 0.
LockedInStress lockedInStress(const std::vector<geometry::Sphere>& spheres,
                              const std::vector<geometry::SpherePair>& pairs, double shear_modulus,
                              double poisson, double volume);

}  // namespace rocklab::experiments::agglomerate
