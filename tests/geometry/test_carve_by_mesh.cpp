#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "rocklab/geometry/carve_by_mesh.h"
#include "rocklab/geometry/hcp_packing.h"
#include "rocklab/geometry/mesh_generate.h"
#include "rocklab/geometry/mesh_voxels.h"

using namespace rocklab::geometry;

TEST_CASE("points inside a mesh: rays through shared edges and vertices count once", "[geometry]") {
  // A cube's faces are split along diagonals; points on the grid x, y ∈ {-0.5, 0, 0.5}
  // send their rays exactly through face diagonals (x = y) and vertices' columns.
  const TriangleMesh box = boxMesh(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  std::vector<Vec3> points;
  std::vector<bool> expected;
  for (double x : {-1.5, -1.0 + 1e-9, -0.5, 0.0, 0.5, 0.999, 1.5})
    for (double y : {-1.5, -0.5, 0.0, 0.5, 1.5})
      for (double z : {-2.0, -0.5, 0.0, 0.7, 2.0}) {
        points.emplace_back(x, y, z);
        expected.push_back(std::abs(x) < 1 && std::abs(y) < 1 && std::abs(z) < 1);
      }
  CHECK(pointsInside(box, points) == expected);
  // Rays through the box's vertical edges and corners' columns (x, y = ±1 exactly)
  // are on the surface: either answer, but no crash and the interior stays right.
  const TriangleMesh ball = icosphere(3, 1.0);
  Rng rng(9);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p(rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2));
    if (std::abs(p.norm() - 0.99) < 0.02) continue;  // between the faces and the vertices' sphere
    CHECK(pointsInside(ball, {p})[0] == (p.norm() < 0.99));
  }
}

TEST_CASE("carve by mesh: keeps the centres inside an ellipsoid, placed centroid to centroid",
          "[geometry]") {
  const double r = 1.0;
  std::vector<Sphere> agglomerate = hcpPacking(r, 40.0, 0.0);
  for (Sphere& s : agglomerate)
    s.centre += Vec3(100, -5, 3);  // anywhere: the mesh follows the centroid
  const Vec3 centroid(100, -5, 3);
  // The ellipsoid is generated away from the origin; it is moved onto the agglomerate.
  TriangleMesh ellipsoid = ellipsoidMesh(15, 10, 7, 4);
  for (Vec3& v : ellipsoid.vertices) v += Vec3(-50, 20, 0);
  CarveOptions options;
  options.mesh_name = "ellipsoid";
  const CarveResult out = carveByMesh(agglomerate, ellipsoid, options);
  REQUIRE(out.spheres.size() > 500);
  std::size_t expected_inside = 0, checked = 0;
  for (const Sphere& s : agglomerate) {
    const Vec3 q = s.centre - centroid;
    const double f = std::pow(q.x() / 15, 2) + std::pow(q.y() / 10, 2) + std::pow(q.z() / 7, 2);
    if (f < 0.99) ++expected_inside;  // safely inside the tessellated surface
    if (f < 0.99 || f > 1.01) ++checked;
  }
  CHECK(out.spheres.size() >= expected_inside);
  CHECK(out.spheres.size() <= expected_inside + (agglomerate.size() - checked));
  for (const Sphere& s : out.spheres) {
    const Vec3 q = s.centre - centroid;
    CHECK(std::pow(q.x() / 15, 2) + std::pow(q.y() / 10, 2) + std::pow(q.z() / 7, 2) < 1.01);
  }
  // Porosity against the mesh volume, and the HCP contacts survive inside.
  CHECK(out.structure.envelope_volume ==
        Approx(4.0 / 3.0 * std::numbers::pi * 15 * 10 * 7).epsilon(0.01));
  CHECK(out.structure.porosity > kHcpPorosity - 0.02);
  CHECK(out.structure.coordination_number > 9);
}

TEST_CASE("carve by mesh: scaled to a size, open meshes and too small agglomerates rejected",
          "[geometry]") {
  const std::vector<Sphere> agglomerate = hcpPacking(1.0, 40.0, 0.0);
  CarveOptions options;
  options.size = 20.0;  // equivalent diameter
  const CarveResult out = carveByMesh(agglomerate, icosphere(3, 1.0), options);
  CHECK(out.structure.envelope_volume == Approx(std::numbers::pi * 20 * 20 * 20 / 6).epsilon(1e-9));
  // Scaled to the volume of a 20 diameter ball, the icosphere's vertices lie a little beyond 10.
  for (const Sphere& s : out.spheres) CHECK(s.centre.norm() < 10.1);
  CHECK(out.spheres.size() > 400);

  TriangleMesh open = icosphere(2, 10.0);
  open.triangles.pop_back();
  options = CarveOptions{};
  options.mesh_name = "scan.stl";
  CHECK_THROWS_AS(carveByMesh(agglomerate, open, options), MeshCheckError);
  CHECK_THROWS_WITH(carveByMesh(agglomerate, open, options),
                    Catch::Contains("scan.stl") && Catch::Contains("not closed") &&
                        Catch::Contains("3 open boundary edges"));
  CHECK_THROWS_WITH(carveByMesh(agglomerate, icosphere(2, 30.0), options),
                    Catch::Contains("generate a larger agglomerate"));
  options.size = -1;
  CHECK_THROWS_WITH(carveByMesh(agglomerate, icosphere(2, 1.0), options),
                    Catch::Contains("size = -1"));
}
