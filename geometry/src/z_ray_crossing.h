#pragma once
// Where a ray along +z at (px, py) crosses a triangle: the one inside test of
// geometry/ (grid columns of mesh_voxels and single points), internal to
// rocklab_geometry.
//
// A ray through a shared edge or vertex must be counted by exactly one of the
// triangles there, or the crossing count of a closed surface breaks. The edge
// functions w are computed for an edge u→v as cross_z(u − p, v − p), which is exactly
// the negation of the neighbour's (it runs the edge v→u), and a zero w is owned by the
// triangle whose edge, taken counter-clockwise in the projection, points "up" (dy > 0,
// or dy = 0 and dx < 0): the top-left rule of rasterisers.
#include <optional>

#include "rocklab/geometry/vec.h"

namespace rocklab::geometry::detail {

struct ZCrossing {
  double z;
  int sign;  // +1 entering (triangle faces −z), −1 leaving
};

inline std::optional<ZCrossing> zRayCrossing(const Vec3& a, const Vec3& b, const Vec3& c, double px,
                                             double py) {
  const double nz = (b - a).cross(c - a).z();
  if (nz == 0) return std::nullopt;  // vertical triangle: the ray runs along it
  const double s = nz > 0 ? 1.0 : -1.0;
  auto covers = [&](const Vec3& u, const Vec3& v, double& w) {
    w = (u.x() - px) * (v.y() - py) - (v.x() - px) * (u.y() - py);
    if (s * w != 0) return s * w > 0;
    const double dx = s * (v.x() - u.x()), dy = s * (v.y() - u.y());
    return dy > 0 || (dy == 0 && dx < 0);
  };
  double w0, w1, w2;
  if (!covers(b, c, w0) || !covers(c, a, w1) || !covers(a, b, w2)) return std::nullopt;
  const double sum = w0 + w1 + w2;
  // On a vertex every weight but one is zero; the sum is never zero for nz != 0.
  const double z = (w0 * a.z() + w1 * b.z() + w2 * c.z()) / sum;
  return ZCrossing{z, nz < 0 ? 1 : -1};
}

}  // namespace rocklab::geometry::detail
