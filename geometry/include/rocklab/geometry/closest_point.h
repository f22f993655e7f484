#pragma once
// Closest points on the primitives that walls are made of. Each function takes
// the query point and returns the point of the primitive nearest to it.
#include <span>

#include "rocklab/geometry/vec.h"

namespace rocklab::geometry {

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision
/// Detection, 5.1.5: Voronoi regions of vertices, then edges, then the face).
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Closest point on a planar convex polygon given by its vertices in order.
/// The polygon is split into a fan of triangles around vertex 0.
Vec3 closestPointOnConvexPolygon(const Vec3& p, std::span<const Vec3> vertices);

}  // namespace rocklab::geometry
