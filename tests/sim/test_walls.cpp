// Walls: a mesh plane must act exactly like the analytic plane (also on edges
// and vertices); polygons, moving walls, removal.
#include <catch2/catch.hpp>
#include <cmath>

#include "support.h"

using namespace rocklab;
using test::Vec3;

namespace {
/// Drops a ball (with spin and sideways speed) on the floor given by `wall`;
/// returns its state after the bounce.
std::pair<Vec3, Vec3> bounce(const sim::Wall& wall, const Vec3& start) {
  auto model = test::linearModel(2e7, 0.4, 0.2);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls.push_back(wall);
  auto s = test::sphere(start, 0.01, {0.3, -0.2, -1.0});
  s.omega = Vec3(5, 3, -2);
  sim::World w(model, {s}, 1);
  for (int k = 0; k < 4000; ++k) w.step();
  return {w.particles().position[0], w.particles().velocity[0]};
}
}  // namespace

TEST_CASE("mesh floor = analytic floor - on a face - an edge and a vertex", "[walls]") {
  sim::Wall plane = test::floorPlane();
  sim::Wall mesh = plane;
  mesh.shape = sim::WallShape::Mesh;
  // A 3 x 3 grid of vertices, two triangles per square: diagonals and a vertex at the origin.
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) mesh.mesh.vertices.emplace_back(0.2 * i, 0.2 * j, 0.0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const std::uint32_t a = j * 3 + i, b = a + 1, c = a + 4, d = a + 3;
      mesh.mesh.triangles.push_back({a, b, c});
      mesh.mesh.triangles.push_back({a, c, d});
    }
  REQUIRE(mesh.mesh.validate().empty());
  for (const Vec3& start : {Vec3(0.05, -0.11, 0.0105),   // inside a face
                            Vec3(-0.1, -0.1, 0.0105),    // on a diagonal edge
                            Vec3(-0.001, 0.0, 0.0105)}) {  // next to the centre vertex
    const auto [xp, vp] = bounce(plane, start);
    const auto [xm, vm] = bounce(mesh, start);
    INFO("start " << start.transpose());
    CHECK(vp.z() > 0);  // it bounced
    CHECK((xp - xm).norm() < 1e-12);
    CHECK((vp - vm).norm() < 1e-10);
  }
}

TEST_CASE("a removed gate releases the ball; a moving wall carries it", "[walls]") {
  auto model = test::linearModel(2e7, 0.5, 0.3);
  model.gravity = Vec3(0, 0, -9.81);
  sim::Wall gate;
  gate.name = "gate";
  gate.shape = sim::WallShape::Polygon;
  gate.vertices = {{-0.05, -0.05, 0}, {0.05, -0.05, 0}, {0.05, 0.05, 0}, {-0.05, 0.05, 0}};
  gate.material = 1;
  gate.active_until = 0.1;
  model.walls.push_back(gate);
  sim::World w(model, {test::sphere({0, 0, 0.0102}, 0.01)}, 1);
  while (w.time() < 0.1) w.step();
  CHECK(w.particles().position[0].z() == Approx(0.01).margin(2e-4));  // rests on the gate
  while (w.time() < 0.2) w.step();
  CHECK(w.particles().position[0].z() < -0.03);  // fell through after removal

  // A floor moving sideways at 0.2 m/s drags a resting ball until its contact point
  // moves with the floor: friction impulse J gives m v = J, (2/5) m r^2 w = J r and
  // v + w r = v_floor, so v = 2/7 v_floor.
  auto m2 = test::linearModel(2e7, 0.5, 0.3);
  m2.gravity = Vec3(0, 0, -9.81);
  sim::Wall belt = test::floorPlane();
  belt.motion.velocity = Vec3(0.2, 0, 0);
  m2.walls.push_back(belt);
  sim::World w2(m2, {test::sphere({0, 0, 0.00999}, 0.01)}, 1);
  while (w2.time() < 0.3) w2.step();
  CHECK(w2.particles().velocity[0].x() == Approx(2.0 / 7.0 * 0.2).epsilon(0.02));
}
