#pragma once
// Which points of a regular grid (or any given points) lie inside a closed mesh, and
// how far each inside grid point is from the outside (a distance transform). Both
// clump generators and the coverage bookkeeping of their greedy selection work on
// this grid; carving agglomerates asks for single points.
//
// Inside test: for every (x, y) column a ray along +z meets the triangles whose
// projection contains the column; entering crossings (triangle facing −z) add one,
// leaving ones subtract one, and a cell centre is inside where the running count is
// positive. Triangles are binned to the columns their xy bounding box covers, so the
// cost is about (triangles + columns crossed). The columns are offset from the cell
// grid's symmetric positions by small irrational fractions of a cell so that a ray
// does not run exactly through the shared edge of two triangles (a cube's diagonal,
// say); where one does anyway (given points), the crossing test's tie rule counts the
// edge once (src/z_ray_crossing.h).
#include <array>
#include <cstdint>
#include <vector>

#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

struct InsideGrid {
  Vec3 origin = Vec3::Zero();  // m, centre of cell (0, 0, 0)
  double h = 0;                // m, cell size
  std::array<int, 3> n{0, 0, 0};
  std::vector<std::uint8_t> inside;  // [n0*n1*n2], index (i*n1 + j)*n2 + k
  std::vector<float> distance;       // [same] m, distance transform (0 outside); filled by computeDistance

  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(i) * n[1] + j) * n[2] + k;
  }
  Vec3 centre(int i, int j, int k) const { return origin + h * Vec3(i, j, k); }
  std::size_t insideCount() const;
};

/// Grid of `cells_across` cells along the mesh's largest extent, one empty cell
/// of margin on every side. The mesh must be closed and outward (checkAndRepairMesh).
InsideGrid voxelizeInside(const TriangleMesh& mesh, int cells_across);

/// For every point, whether it lies inside the closed, outward mesh (the same z-ray
/// crossing count as voxelizeInside; triangles binned to xy columns). Points on the
/// surface may go either way.
std::vector<bool> pointsInside(const TriangleMesh& mesh, const std::vector<Vec3>& points);

/// Fills grid.distance: Euclidean distance from each inside cell centre to the
/// nearest outside cell centre minus h/2 (≈ distance to the surface, ± h/2);
/// exact squared distance transform of Felzenszwalb & Huttenlocher (2012), three 1-D passes.
void computeDistance(InsideGrid& grid);

}  // namespace rocklab::geometry
