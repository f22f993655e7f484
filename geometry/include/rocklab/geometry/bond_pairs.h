#pragma once
// Which spheres of an agglomerate touch: the pairs that get a bond, and the
// contacts the structure statistics count (one rule for both).
#include <cstddef>
#include <utility>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry {

using SpherePair = std::pair<std::size_t, std::size_t>;  // indices, first < second

/// Gap d − r_a − r_b (m): negative when the spheres overlap.
double sphereGap(const Sphere& a, const Sphere& b);

/// The bond rule: gap <= gap_tolerance × min(r_a, r_b) (overlapping pairs included).
bool withinBondGap(const Sphere& a, const Sphere& b, double gap_tolerance);

/// Every pair within the bond gap, sorted (a < b, lexicographic); a hash grid, so
/// the cost is linear in the sphere count. Throws std::invalid_argument for a
/// gap_tolerance < 0 or a radius <= 0.
std::vector<SpherePair> bondPairs(const std::vector<Sphere>& spheres, double gap_tolerance);

}  // namespace rocklab::geometry
