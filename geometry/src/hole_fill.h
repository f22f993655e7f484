#pragma once
// Small holes of a scanned surface closed by a patch (mesh_check.cpp, when asked):
// a scan that misses a few triangles is common, and a clump needs a closed surface.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::geometry::detail {

struct HoleFill {
  std::size_t holes_filled = 0;     // boundary loops closed
  std::size_t triangles_added = 0;  // patch triangles
  std::size_t largest_filled = 0;   // edges of the largest loop closed
};

/// Every boundary loop (edges used by one triangle, followed tip to tail) of at
/// most `max_edges` edges is closed by CGAL's minimum-area hole triangulation
/// (Polygon_mesh_processing::triangulate_hole_polyline, Liepa 2003), its triangles
/// appended to `triangles`, oriented against the loop so that they agree with the
/// surface around it. Larger loops, and boundaries that are not simple loops (a
/// vertex where two holes touch), are left as they are: the closedness check that
/// follows reports them.
HoleFill fillSmallHoles(const std::vector<Vec3>& vertices, std::vector<std::array<std::uint32_t, 3>>& triangles,
                        std::size_t max_edges);

}  // namespace rocklab::geometry::detail
