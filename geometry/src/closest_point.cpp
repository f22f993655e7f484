#include "rocklab/geometry/closest_point.h"

#include <limits>

namespace rocklab::geometry {

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Vertex region A.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  // Vertex region B.
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  // Edge region AB.
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  // Vertex region C.
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  // Edge region AC.
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  // Edge region BC.
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  // Face region: barycentric coordinates (u, v, w) with u = 1 - v - w.
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

Vec3 closestPointOnConvexPolygon(const Vec3& p, std::span<const Vec3> vertices) {
  Vec3 best = vertices[0];
  double bestDist2 = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k + 1 < vertices.size(); ++k) {
    const Vec3 q = closestPointOnTriangle(p, vertices[0], vertices[k], vertices[k + 1]);
    const double d2 = (q - p).squaredNorm();
    if (d2 < bestDist2) {
      bestDist2 = d2;
      best = q;
    }
  }
  return best;
}

}  // namespace rocklab::geometry
