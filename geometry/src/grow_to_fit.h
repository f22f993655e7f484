#pragma once
// The reference's remedy for a tangent sphere that overlaps a sphere outside its
// group (experiments.md §f.4 step 4): a sphere of r_min at the computed centre,
// grown in 0.1 % steps, each time moved off its overlaps with the fixed others,
// until it has at least three contacts. Internal to rocklab_geometry.
#include <optional>

#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/sphere_hash_grid.h"

namespace rocklab::geometry::detail {

// Overlaps below this fraction of the smaller radius are contacts, not overlaps:
// the push-out stops there, and a tangent sphere (round-off ~1e-15) passes.
inline constexpr double kOverlapTolerance = 1e-6;

struct GrowSettings {
  double r_start = 0;         // m, r_min
  double r_cap = 0;           // m, r_max: the sphere never grows beyond it
  double growth_step = 1e-3;  // relative radius increase per step (0.1 %)
  double gap_tolerance = 0;   // contacts by the bond rule (withinBondGap)
  Vec3 bound_centre = Vec3::Zero();
  double bound_radius = 0;     // m, the agglomerate's sphere: a fixed wall while relaxing
  int max_relax_sweeps = 200;  // push-out sweeps per size before the sphere counts as stuck
};

/// Moves `s` off its overlaps with the spheres of `grid` (and back inside the bounding
/// sphere): Gauss-Seidel sweeps, each overlap > kOverlapTolerance × the smaller radius
/// removed in turn by a push along the line of centres. False when overlaps remain
/// after max_relax_sweeps (the sphere is wedged).
bool pushOffOverlaps(Sphere& s, const SphereHashGrid& grid, const GrowSettings& settings);

/// The grown sphere: starting at r_start at `centre` (false → nullopt if it cannot be
/// made to fit there), grown until it has >= 3 contacts; growth also ends at r_cap or
/// when the next size cannot be made to fit (the last fitting size is kept). A result
/// with no contact at all is rejected (it would carry no bond).
std::optional<Sphere> growToFit(const Vec3& centre, const SphereHashGrid& grid,
                                const GrowSettings& settings);

/// Whether `s` overlaps a sphere of `grid` by more than kOverlapTolerance × the smaller radius.
bool overlapsAny(const Sphere& s, const SphereHashGrid& grid);

}  // namespace rocklab::geometry::detail
