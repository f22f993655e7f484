#include "rocklab/geometry/agglomerate_packing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <string>

#include "grow_to_fit.h"
#include "parameter_check.h"
#include "power_cells.h"
#include "rocklab/geometry/tangent_sphere.h"
#include "rocklab/geometry/sphere_hash_grid.h"

namespace rocklab::geometry {

namespace {

void checkParams(const VoidFillParams& p) {
  const char* f = "fillVoids";
  detail::requireParameter(p.r_max > 0 && std::isfinite(p.r_max), f, "r_max", p.r_max,
                           "must be > 0 (m)");
  detail::requireParameter(p.r0 >= 1 && std::isfinite(p.r0), f, "r0", p.r0,
                           "must be >= 1 (r_max / r_min, Eq 5-11)");
  detail::requireParameter(p.agglomerate_radius >= p.r_max && std::isfinite(p.agglomerate_radius),
                           f, "agglomerate_radius", p.agglomerate_radius,
                           "must be >= r_max (" + detail::formatValue(p.r_max) + " m)");
  detail::requireParameter(p.gap_tolerance >= 0 && std::isfinite(p.gap_tolerance), f,
                           "gap_tolerance", p.gap_tolerance,
                           "must be >= 0 (a fraction of the smaller radius)");
  detail::requireParameter(p.max_passes >= 1, f, "max_passes", p.max_passes, "must be >= 1");
}

// Wholly inside the bounding sphere, up to the gap tolerance (a sphere pressed into
// the servo wall of the loose pack overlaps it a little and is still kept).
bool insideBound(const Sphere& s, const VoidFillParams& p) {
  return (s.centre - p.centre).norm() + s.radius <=
         p.agglomerate_radius + p.gap_tolerance * s.radius;
}

void shuffle(std::vector<detail::CellVertices>& cells, Rng& rng) {
  for (std::size_t i = cells.size(); i > 1; --i) std::swap(cells[i - 1], cells[rng.next() % i]);
}

void countFailure(TangentFailure failure, VoidFillReport& r) {
  if (failure == TangentFailure::Degenerate) ++r.rejected_degenerate;
  if (failure == TangentFailure::NoPositiveRoot) ++r.rejected_no_root;
  if (failure == TangentFailure::CentreOutside) ++r.rejected_centre_outside;
}

// Steps 3 and 4 for one group: the sphere to add to its void, if any; the outcome
// is counted in the report.
std::optional<Sphere> fillOneVoid(const std::array<Sphere, 4>& group, const VoidFillParams& params,
                                  const SphereHashGrid& grid,
                                  const detail::GrowSettings& grow, VoidFillReport& report) {
  const TangentSolution solution = innerTangentSphere(group);
  if (!solution.sphere) {
    countFailure(solution.failure, report);
    return std::nullopt;
  }
  const Sphere& tangent = *solution.sphere;
  if (tangent.radius < grow.r_start) {  // condition 1
    ++report.rejected_too_small;
    return std::nullopt;
  }
  if ((tangent.centre - params.centre).norm() > params.agglomerate_radius) {
    ++report.rejected_outside_agglomerate;
    return std::nullopt;
  }
  if (tangent.radius <= params.r_max && insideBound(tangent, params) &&
      !detail::overlapsAny(tangent, grid)) {  // condition 2
    ++report.placed_tangent;
    return tangent;
  }
  const std::optional<Sphere> grown = detail::growToFit(tangent.centre, grid, grow);
  ++(grown ? report.placed_grown : report.rejected_cannot_fit);
  return grown;
}

}  // namespace

VoidFillResult fillVoids(const std::vector<Sphere>& pack, const VoidFillParams& params) {
  checkParams(params);
  VoidFillResult out;
  VoidFillReport& report = out.report;
  report.input_spheres = pack.size();
  double r_largest = params.r_max;
  for (std::size_t i = 0; i < pack.size(); ++i) {
    detail::requireParameter(pack[i].radius > 0, "fillVoids",
                             "radius of pack sphere " + std::to_string(i), pack[i].radius,
                             "must be > 0");
    if (!insideBound(pack[i], params)) {
      ++report.input_dropped;
      continue;
    }
    out.spheres.push_back(pack[i]);
    r_largest = std::max(r_largest, pack[i].radius);
  }
  // Cell: the largest contact distance (both spheres at the largest radius, plus the gap).
  SphereHashGrid grid{r_largest * (2.0 + params.gap_tolerance), {}};
  for (const Sphere& s : out.spheres) grid.insert(s);
  detail::GrowSettings grow;
  grow.r_start = params.r_max / params.r0;  // r_min, Eq 5-11
  grow.r_cap = params.r_max;
  grow.gap_tolerance = params.gap_tolerance;
  grow.bound_centre = params.centre;
  grow.bound_radius = params.agglomerate_radius;

  std::set<detail::CellVertices> tried;
  Rng rng(params.seed);
  for (int pass = 1; pass <= params.max_passes; ++pass) {
    report.passes = pass;
    std::vector<detail::CellVertices> cells;
    for (const detail::CellVertices& c : detail::powerCells(out.spheres))
      if (tried.insert(c).second) cells.push_back(c);
    shuffle(cells, rng);
    std::size_t placed = 0;
    for (const detail::CellVertices& c : cells) {
      ++report.cells_tried;
      const std::optional<Sphere> sphere =
          fillOneVoid({out.spheres[c[0]], out.spheres[c[1]], out.spheres[c[2]], out.spheres[c[3]]},
                      params, grid, grow, report);
      if (!sphere) continue;
      grid.insert(*sphere);
      out.spheres.push_back(*sphere);
      ++placed;
    }
    report.added += placed;
    if (placed == 0) break;
  }
  const double R = params.agglomerate_radius;
  report.structure = structureStatistics(out.spheres, 4.0 / 3.0 * std::numbers::pi * R * R * R,
                                         params.gap_tolerance);
  return out;
}

}  // namespace rocklab::geometry
