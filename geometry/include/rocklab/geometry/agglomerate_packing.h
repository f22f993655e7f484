#pragma once
// Dense random packing of an agglomerate by void filling (experiments.md §f.4,
// steps 2–4): the voids of a packing of spheres (the servo-compacted loose pack of
// equal spheres of r_max, or any other) are filled with progressively smaller
// spheres, each tangent to the four spheres around a void (Eq 5-10), down to
// r_min = r_max / r0 (Eq 5-11).
//
// Steps, per pass:
//   2. groups of four neighbouring spheres = the cells of the regular (power)
//      triangulation of the centres, weights r² (CGAL; Delaunay for equal spheres).
//      The reference's own search (smallest tetrahedron among the neighbours within
//      4 r_max of a random sphere) takes one group per sphere, a subset of these,
//      and leaves flat groups to an unstated rule; the triangulation has every void
//      exactly once, so it fills more of them.
//   3. the inner tangent sphere of each group (innerTangentSphere); its centre
//      must lie inside the bounding sphere;
//   4. condition 1 r >= r_min, else rejected; condition 2 (no overlap with any
//      sphere, hash grid; overlaps up to 1e-6 of the smaller radius are contacts)
//      and r <= r_max and inside the bounding sphere → placed as computed; when
//      condition 1 holds but not the rest, a sphere of r_min at the computed centre
//      is grown in 0.1 % steps, each step pushed off its overlaps with the fixed
//      others (Gauss-Seidel along the lines of centres, until every overlap is below
//      1e-6 of the smaller radius; the bounding sphere is a wall), until it has at
//      least three contacts (the bond gap rule); growth also ends at r_max or when
//      the next size cannot be pushed free (the last fitting size is kept). Rejected
//      when it cannot be pushed free at r_min or touches nothing.
// Passes repeat on the re-triangulated set (the added spheres included) until one
// places nothing; cells already tried (same four spheres) are not tried again: a
// placement only adds obstacles, so a rejected void does not reopen (bar the rare
// grown sphere that touched nothing before), and each pass costs only its new cells.
// Within a pass the cells are visited in a seeded random order (the reference picks
// spheres at random; the seed gives different agglomerates from one pack).
// Deterministic for a given input and seed.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/structure_statistics.h"

namespace rocklab::geometry {

struct VoidFillParams {
  double r_max = 0;               // m, radius of the loose pack's spheres; cap of grown spheres
  double r0 = 4;                  // r_max / r_min (Eq 5-11), >= 1
  double agglomerate_radius = 0;  // m, the bounding sphere: spheres are kept wholly inside it
  Vec3 centre = Vec3::Zero();     // m, its centre
  double gap_tolerance = 1e-3;    // bond gap, a fraction of the smaller radius (contacts, bonds)
  std::uint64_t seed = 1;         // visiting order of the cells
  int max_passes = 100;
};

struct VoidFillReport {
  StructureStatistics
      structure;  // of the result in the bounding sphere (porosity against its volume)
  std::size_t input_spheres = 0;  // as given
  std::size_t input_dropped = 0;  // not wholly inside the bounding sphere (up to the gap tolerance)
  std::size_t added = 0;          // = placed_tangent + placed_grown
  int passes = 0;                 // including the last one that placed nothing
  std::size_t cells_tried = 0;    // distinct groups of four
  std::size_t placed_tangent = 0;                // placed as computed (conditions 1 and 2)
  std::size_t placed_grown = 0;                  // grown from r_min
  std::size_t rejected_degenerate = 0;           // coplanar group
  std::size_t rejected_no_root = 0;              // no positive radius
  std::size_t rejected_centre_outside = 0;       // centre outside its tetrahedron
  std::size_t rejected_too_small = 0;            // r < r_min (condition 1)
  std::size_t rejected_outside_agglomerate = 0;  // centre outside the bounding sphere
  std::size_t rejected_cannot_fit = 0;  // could not be grown free of overlaps with a contact
};

struct VoidFillResult {
  std::vector<Sphere>
      spheres;  // the kept input spheres first (in input order), then the added ones
  VoidFillReport report;
};

/// Fills the voids of `pack` (see the top of this header). Throws std::invalid_argument
/// naming the parameter for r_max <= 0, r0 < 1, agglomerate_radius < r_max,
/// gap_tolerance < 0, max_passes < 1, or a sphere radius <= 0.
VoidFillResult fillVoids(const std::vector<Sphere>& pack, const VoidFillParams& params);

}  // namespace rocklab::geometry
