#include <catch2/catch.hpp>

#include "rocklab/geometry/closest_point.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/triangle_mesh.h"

using namespace rocklab::geometry;

TEST_CASE("closest point on a triangle: face - edge and vertex regions", "[geometry]") {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  CHECK(closestPointOnTriangle(Vec3(0.2, 0.2, 3), a, b, c).isApprox(Vec3(0.2, 0.2, 0)));
  CHECK(closestPointOnTriangle(Vec3(0.5, -2, 1), a, b, c).isApprox(Vec3(0.5, 0, 0)));
  CHECK(closestPointOnTriangle(Vec3(1, 1, 0), a, b, c).isApprox(Vec3(0.5, 0.5, 0)));
  CHECK(closestPointOnTriangle(Vec3(-1, -1, 0), a, b, c).isApprox(a));
  CHECK(closestPointOnTriangle(Vec3(3, -1, 0), a, b, c).isApprox(b));
  CHECK(closestPointOnTriangle(Vec3(-1, 3, 2), a, b, c).isApprox(c));
}

TEST_CASE("closest point on a convex polygon and on a mesh agree", "[geometry]") {
  const std::vector<Vec3> square{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  TriangleMesh mesh;
  mesh.vertices = square;
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  REQUIRE(mesh.validate().empty());
  Rng rng(3);
  for (int k = 0; k < 200; ++k) {
    const Vec3 p(rng.uniform(-1, 2), rng.uniform(-1, 2), rng.uniform(-1, 1));
    const Vec3 q = closestPointOnConvexPolygon(p, square);
    CHECK((q - mesh.closestPoint(p)).norm() < 1e-14);
    // The answer is the clamp of p onto the unit square in the plane z = 0.
    CHECK((q - Vec3(std::clamp(p.x(), 0.0, 1.0), std::clamp(p.y(), 0.0, 1.0), 0.0)).norm() < 1e-14);
  }
}
