#pragma once
// Structure of a sphere assembly (an agglomerate): porosity, coordination number,
// initial overlaps. One function for every generator (void filling, HCP, carving),
// so their figures compare.
#include <cstddef>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry {

struct StructureStatistics {
  std::size_t sphere_count = 0;
  std::size_t contact_count = 0;      // pairs within the bond gap (bondPairs): the bonds
  std::size_t overlapping_pairs = 0;  // pairs with gap < 0
  double solid_volume = 0;            // m^3, Σ sphere volumes − Σ pair lens volumes (see below)
  double envelope_volume = 0;         // m^3, as given (bounding sphere, mesh volume)
  double porosity = 0;                // 1 − solid_volume / envelope_volume
  double coordination_number = 0;     // 2 contact_count / sphere_count
  double max_overlap = 0;           // m, largest r_a + r_b − d over the pairs (0 if none overlap)
  double max_overlap_fraction = 0;  // largest (r_a + r_b − d) / min(r_a, r_b)
};

/// Statistics of `spheres` in an envelope of `envelope_volume`. Overlaps are counted
/// once: the lens volume of every overlapping pair is subtracted from the sum of the
/// sphere volumes (a sphere wholly inside another counts as that lens); points in
/// three or more spheres are not corrected for, which is exact while no three spheres
/// share a point and negligible for the small overlaps of a packing. Contacts follow
/// the bond rule (gap <= gap_tolerance × the smaller radius). Throws
/// std::invalid_argument for envelope_volume <= 0 (and as bondPairs does).
StructureStatistics structureStatistics(const std::vector<Sphere>& spheres, double envelope_volume,
                                        double gap_tolerance);

/// Centre of the spheres with their volumes as weights (the centre of mass of equal-
/// density spheres, overlaps counted twice), m; the origin for no spheres.
Vec3 volumeCentroid(const std::vector<Sphere>& spheres);

/// Volume of the intersection of two spheres (the lens), m^3.
double lensVolume(const Sphere& a, const Sphere& b);

}  // namespace rocklab::geometry
