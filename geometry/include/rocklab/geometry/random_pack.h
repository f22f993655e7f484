#pragma once
// A random pack of equal spheres in a spherical container by geometric overlap
// removal: the stand-in, for tests and measurements, of the servo-compacted loose
// pack (experiments.md §f.4 step 1) that the DEM engine makes. It has no forces, so
// no locked-in stress, and its density is set by the count.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry {

struct RandomPackResult {
  std::vector<Sphere> spheres;
  int sweeps = 0;          // push-apart sweeps used
  double max_overlap = 0;  // m, largest overlap of the last sweep (pair or wall); 0 when converged
};

/// `count` spheres of `radius`, centres drawn uniformly (seeded) in the container
/// sphere of `container_radius` at the origin, then moved apart: Gauss-Seidel sweeps
/// over the pairs within reach (bondPairs with a gap of 0.3 r, rebuilt when a sphere
/// has moved 0.15 r), each overlapping pair pushed apart by
/// half its overlap each, the container a fixed wall, until every overlap is below
/// 1e-6 r or `max_sweeps` have run. Dense counts (solid fraction above about 0.6)
/// may not converge: check max_overlap. Throws std::invalid_argument for radius <= 0
/// or container_radius < radius.
RandomPackResult relaxedRandomPack(std::size_t count, double radius, double container_radius,
                                   std::uint64_t seed, int max_sweeps = 20000);

}  // namespace rocklab::geometry
