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

TEST_CASE("mesh validation names the problem", "[geometry]") {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  mesh.triangles = {{0, 1, 2}};
  CHECK(mesh.validate() == "triangle 0 has zero area");
  mesh.triangles = {{0, 1, 5}};
  CHECK(mesh.validate().find("refers to vertex 5") != std::string::npos);
}

TEST_CASE("lattices follow the LIGGGHTS convention", "[geometry]") {
  const auto bcc = latticePoints(LatticeKind::BodyCentred, 2.0, Vec3(0.25, 0.25, 0.25), Vec3::Zero(), {2, 1, 1});
  REQUIRE(bcc.size() == 4);
  CHECK(bcc[0].isApprox(Vec3(0.5, 0.5, 0.5)));
  CHECK(bcc[1].isApprox(Vec3(1.5, 1.5, 1.5)));
  CHECK(bcc[2].isApprox(Vec3(2.5, 0.5, 0.5)));
  const auto fcc = latticePoints(LatticeKind::FaceCentred, 1.0, Vec3::Zero(), Vec3::Zero(), {3, 3, 3});
  CHECK(fcc.size() == 108);
}

TEST_CASE("random insertion: seeded - inside the region - no overlaps", "[geometry]") {
  std::vector<double> radii(300);
  Rng r0(11);
  for (double& r : radii) r = r0.uniform(0.002, 0.014);  // 7:1 size ratio
  Rng a(5), b(5);
  const Vec3 lo(0, 0, 0), hi(0.3, 0.3, 0.3);
  const auto pa = randomNonOverlapping(radii, lo, hi, {}, a);
  const auto pb = randomNonOverlapping(radii, lo, hi, {}, b);
  REQUIRE(pa.size() == radii.size());
  CHECK(pa == pb);
  for (std::size_t i = 0; i < pa.size(); ++i) {
    CHECK(((pa[i].array() - radii[i]) >= 0).all());
    CHECK(((pa[i].array() + radii[i]) <= 0.3).all());
    for (std::size_t j = i + 1; j < pa.size(); ++j) CHECK((pa[i] - pa[j]).norm() >= radii[i] + radii[j]);
  }
}
