#include "rocklab/geometry/triangle_mesh.h"

#include <limits>
#include <sstream>

#include "rocklab/geometry/closest_point.h"

namespace rocklab::geometry {

AABB TriangleMesh::bounds() const {
  AABB box;
  for (const Vec3& v : vertices) box.extend(v);
  return box;
}

Vec3 TriangleMesh::closestPoint(const Vec3& p) const {
  Vec3 best = Vec3::Zero();
  double bestDist2 = std::numeric_limits<double>::infinity();
  for (const auto& t : triangles) {
    const Vec3 q = closestPointOnTriangle(p, vertices[t[0]], vertices[t[1]], vertices[t[2]]);
    const double d2 = (q - p).squaredNorm();
    if (d2 < bestDist2) {
      bestDist2 = d2;
      best = q;
    }
  }
  return best;
}

std::string TriangleMesh::nonFiniteVertex() const {
  for (std::size_t k = 0; k < vertices.size(); ++k)
    if (!vertices[k].allFinite()) {
      std::ostringstream msg;
      msg << "vertex " << k << " has " << (vertices[k].hasNaN() ? "a NaN" : "an infinite") << " coordinate ("
          << vertices[k].x() << ", " << vertices[k].y() << ", " << vertices[k].z() << ")";
      return msg.str();
    }
  return {};
}

std::string TriangleMesh::validate() const {
  std::ostringstream msg;
  if (triangles.empty()) return "the mesh has no triangles";
  if (std::string bad = nonFiniteVertex(); !bad.empty()) return bad;
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    for (std::uint32_t idx : triangles[k]) {
      if (idx >= vertices.size()) {
        msg << "triangle " << k << " refers to vertex " << idx << " but the mesh has "
            << vertices.size() << " vertices";
        return msg.str();
      }
    }
    const auto& t = triangles[k];
    const double area2 =
        (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).norm();
    if (!(area2 > 0.0)) {
      msg << "triangle " << k << " has zero area";
      return msg.str();
    }
  }
  return {};
}

}  // namespace rocklab::geometry
