#include "power_cells.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_data_structure_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <utility>

namespace rocklab::geometry::detail {

namespace {
// Exact predicates (the orientation and power tests decide the combinatorics, so
// nearly degenerate packings such as lattices never break the triangulation);
// inexact constructions are enough: we only read the cells.
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase =
    CGAL::Triangulation_vertex_base_with_info_3<std::size_t, Kernel,
                                                CGAL::Regular_triangulation_vertex_base_3<Kernel>>;
using CellBase = CGAL::Regular_triangulation_cell_base_3<Kernel>;
using DataStructure = CGAL::Triangulation_data_structure_3<VertexBase, CellBase>;
using PowerTriangulation = CGAL::Regular_triangulation_3<Kernel, DataStructure>;
}  // namespace

std::vector<CellVertices> powerCells(const std::vector<Sphere>& spheres) {
  std::vector<std::pair<Kernel::Weighted_point_3, std::size_t>> points;
  points.reserve(spheres.size());
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const Sphere& s = spheres[i];
    points.emplace_back(
        Kernel::Weighted_point_3(Kernel::Point_3(s.centre.x(), s.centre.y(), s.centre.z()),
                                 s.radius * s.radius),
        i);
  }
  const PowerTriangulation triangulation(points.begin(), points.end());
  std::vector<CellVertices> cells;
  if (triangulation.dimension() < 3) return cells;
  cells.reserve(triangulation.number_of_finite_cells());
  for (auto cell = triangulation.finite_cells_begin(); cell != triangulation.finite_cells_end();
       ++cell) {
    CellVertices v{cell->vertex(0)->info(), cell->vertex(1)->info(), cell->vertex(2)->info(),
                   cell->vertex(3)->info()};
    std::sort(v.begin(), v.end());
    cells.push_back(v);
  }
  std::sort(cells.begin(), cells.end());
  return cells;
}

}  // namespace rocklab::geometry::detail
