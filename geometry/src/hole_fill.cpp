#include "hole_fill.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include <algorithm>
#include <iterator>
#include <map>

#include "mesh_edges.h"

namespace rocklab::geometry::detail {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Tri = std::array<std::uint32_t, 3>;
}  // namespace

HoleFill fillSmallHoles(const std::vector<Vec3>& vertices, std::vector<Tri>& triangles, std::size_t max_edges) {
  HoleFill out;
  if (max_edges < 3) return out;
  // A boundary edge is used by one triangle. The hole loop runs b -> a where that
  // triangle runs a -> b: the patch must run the way the surface does across it.
  std::multimap<std::uint32_t, std::uint32_t> next;  // hole loop: from -> to (against the surface)
  const std::vector<EdgeUse> uses = edgeUses(triangles);
  for (std::size_t i = 0; i < uses.size(); ++i) {
    if ((i > 0 && uses[i - 1].key == uses[i].key) || (i + 1 < uses.size() && uses[i + 1].key == uses[i].key)) continue;
    const auto lo = static_cast<std::uint32_t>(uses[i].key >> 32), hi = static_cast<std::uint32_t>(uses[i].key);
    if (uses[i].forward)
      next.emplace(hi, lo);  // the triangle runs lo -> hi
    else
      next.emplace(lo, hi);
  }
  std::map<std::uint32_t, bool> used;
  for (const auto& [start, first] : next) {
    if (used[start] || next.count(start) != 1) continue;
    // Follow the loop; give up on a vertex with two ways on (touching holes).
    std::vector<std::uint32_t> loop{start};
    bool simple = true;
    for (std::uint32_t v = first; v != start; ) {
      if (next.count(v) != 1 || loop.size() > max_edges || used[v]) {
        simple = false;
        break;
      }
      loop.push_back(v);
      v = next.find(v)->second;
    }
    for (std::uint32_t v : loop) used[v] = true;
    if (!simple || loop.size() > max_edges || loop.size() < 3) continue;
    std::vector<Kernel::Point_3> polyline;
    for (std::uint32_t v : loop) polyline.emplace_back(vertices[v].x(), vertices[v].y(), vertices[v].z());
    std::vector<CGAL::Triple<int, int, int>> patch;
    CGAL::Polygon_mesh_processing::triangulate_hole_polyline(polyline, std::back_inserter(patch));
    if (patch.empty()) continue;  // CGAL found no triangulation: left for the check to report
    // The patch triangle on the loop's first edge must run loop[0] -> loop[1] (the
    // surface's own edge runs loop[1] -> loop[0]); if it runs back, so do all of them.
    bool reversed = false;
    for (const auto& p : patch) {
      const std::array<int, 3> c = {p.first, p.second, p.third};
      for (int e = 0; e < 3; ++e)
        if (c[e] == 1 && c[(e + 1) % 3] == 0) reversed = true;
    }
    for (const auto& p : patch) {
      const auto at = [&loop](int k) { return loop[static_cast<std::size_t>(k)]; };
      triangles.push_back(reversed ? Tri{at(p.first), at(p.third), at(p.second)}
                                   : Tri{at(p.first), at(p.second), at(p.third)});
    }
    ++out.holes_filled;
    out.triangles_added += patch.size();
    out.largest_filled = std::max(out.largest_filled, loop.size());
  }
  return out;
}

}  // namespace rocklab::geometry::detail
