#pragma once
// Groups of four neighbouring spheres: the cells of the regular (power) triangulation
// of the sphere centres weighted by r² (CGAL). Internal to rocklab_geometry: CGAL
// stays out of the public headers.
#include <array>
#include <cstddef>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry::detail {

using CellVertices = std::array<std::size_t, 4>;  // sphere indices, ascending

/// The finite cells of the regular triangulation of `spheres` (weights r²), each as
/// its four sphere indices in ascending order, the list sorted. For equal radii this
/// is the Delaunay tetrahedralisation of the centres; for a polydisperse set the
/// regular (power) triangulation is the right one: its cells join the spheres whose
/// power cells (bounded by the radical planes between sphere surfaces) meet, i.e. the
/// spheres around one void, where Delaunay of the bare centres can join a small
/// sphere to neighbours hidden behind a large one. The order is canonical (sorted), so it depends
/// on the spheres only, not on CGAL's insertion order or internal storage. Spheres hidden by the
/// power diagram (a centre deep inside a larger sphere) belong to no cell.
std::vector<CellVertices> powerCells(const std::vector<Sphere>& spheres);

}  // namespace rocklab::geometry::detail
