#include "grow_to_fit.h"

#include <algorithm>
#include <cmath>

#include "rocklab/geometry/bond_pairs.h"

namespace rocklab::geometry::detail {

namespace {

double allowedOverlap(const Sphere& a, const Sphere& b) {
  return kOverlapTolerance * std::min(a.radius, b.radius);
}

int contactCount(const Sphere& s, const SphereHashGrid& grid, double gap_tolerance) {
  int contacts = 0;
  grid.forEachNear(s.centre, [&](const SphereHashGrid::Entry& e) {
    contacts += withinBondGap(s, e.sphere, gap_tolerance) ? 1 : 0;
  });
  return contacts;
}

}  // namespace

bool overlapsAny(const Sphere& s, const SphereHashGrid& grid) {
  return grid.anyNear(s.centre, [&](const SphereHashGrid::Entry& e) {
    return -sphereGap(s, e.sphere) > allowedOverlap(s, e.sphere);
  });
}

bool pushOffOverlaps(Sphere& s, const SphereHashGrid& grid, const GrowSettings& settings) {
  for (int sweep = 0; sweep < settings.max_relax_sweeps; ++sweep) {
    bool pushed = false;
    // The neighbours are gathered once per sweep (the sphere moves by less than a cell).
    std::vector<Sphere> near;
    grid.forEachNear(s.centre, [&](const SphereHashGrid::Entry& e) { near.push_back(e.sphere); });
    for (const Sphere& other : near) {
      const Vec3 d = s.centre - other.centre;
      const double dist = d.norm();
      const double overlap = s.radius + other.radius - dist;
      if (!(overlap > allowedOverlap(s, other))) continue;
      if (!(dist > 0)) return false;  // concentric: no direction to push along
      s.centre += (overlap / dist) * d;
      pushed = true;
    }
    // The agglomerate's bounding sphere is a wall: push back inside.
    const Vec3 out = s.centre - settings.bound_centre;
    const double excess = out.norm() + s.radius - settings.bound_radius;
    if (excess > kOverlapTolerance * s.radius) {
      if (!(s.radius < settings.bound_radius)) return false;
      s.centre -= (excess / out.norm()) * out;
      pushed = true;
    }
    if (!pushed) return true;
  }
  return false;
}

std::optional<Sphere> growToFit(const Vec3& centre, const SphereHashGrid& grid,
                                const GrowSettings& settings) {
  Sphere s{centre, settings.r_start};
  if (!pushOffOverlaps(s, grid, settings)) return std::nullopt;
  Sphere fitted = s;
  while (contactCount(fitted, grid, settings.gap_tolerance) < 3 && fitted.radius < settings.r_cap) {
    Sphere next{fitted.centre,
                std::min(fitted.radius * (1 + settings.growth_step), settings.r_cap)};
    if (!pushOffOverlaps(next, grid, settings)) break;  // wedged: keep the last size that fitted
    fitted = next;
  }
  if (contactCount(fitted, grid, settings.gap_tolerance) == 0) return std::nullopt;
  return fitted;
}

}  // namespace rocklab::geometry::detail
