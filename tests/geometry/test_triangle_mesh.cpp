#include <catch2/catch.hpp>

#include <string>

#include "rocklab/geometry/triangle_mesh.h"

using namespace rocklab::geometry;

TEST_CASE("mesh validation names the problem", "[geometry]") {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  mesh.triangles = {{0, 1, 2}};
  CHECK(mesh.validate() == "triangle 0 has zero area");
  mesh.triangles = {{0, 1, 5}};
  CHECK(mesh.validate().find("refers to vertex 5") != std::string::npos);
}
