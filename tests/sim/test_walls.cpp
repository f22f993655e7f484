// Walls: a mesh plane must act exactly like the analytic plane (also on edges
// and vertices); polygons, moving walls, removal.
#include <catch2/catch.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include "rocklab/geometry/frustum_mesh.h"
#include "rocklab/sim/output/checkpoint.h"
#include "support.h"
#include "wall_runtime.h"

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

namespace {
/// A 90-degree groove along y (faces z = -x and z = x, two triangles each) as
/// one mesh wall, and the same two faces as plane walls.
sim::Wall grooveMesh() {
  sim::Wall w = test::floorPlane();
  w.name = "groove";
  w.shape = sim::WallShape::Mesh;
  w.mesh.vertices = {{-0.1, -0.2, 0.1}, {-0.1, 0.2, 0.1}, {0, -0.2, 0}, {0, 0.2, 0}, {0.1, -0.2, 0.1}, {0.1, 0.2, 0.1}};
  w.mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
  return w;
}
std::vector<sim::Wall> groovePlanes() {
  return {test::plane("left", Vec3::Zero(), Vec3(1, 0, 1)), test::plane("right", Vec3::Zero(), Vec3(-1, 0, 1))};
}
/// A ball dropped off-centre into the groove with spin and a speed along it:
/// it rocks from face to face, slides and rolls along the crease, and settles.
sim::Model grooveModel(const std::vector<sim::Wall>& walls) {
  // Soft (1e5 N/m): the resting overlaps are about a micrometre, not a few
  // nanometres, so round-off does not decide whether a face is touched.
  auto model = test::linearModel(1e5, 0.4, 0.2);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls = walls;
  return model;
}
sim::SphereSpec grooveBall() {
  auto s = test::sphere(Vec3(0.004, -0.05, 0.02), 0.01, {-0.2, 0.3, -0.5});
  s.omega = Vec3(4, -3, 2);
  return s;
}
}  // namespace

TEST_CASE("a ball in a mesh's concave crease touches both faces: as in the groove of two planes", "[walls]") {
  // One contact per ball and mesh (the nearest face) would let the ball sink into
  // the other face; each touch is its own contact with its own shear spring.
  const double r = 0.01;
  sim::World planes(grooveModel(groovePlanes()), {grooveBall()}, 1);
  sim::World mesh(grooveModel({grooveMesh()}), {grooveBall()}, 1);
  int both = 0, differ = 0;
  std::size_t on_planes = 0, on_mesh = 0;
  while (planes.time() < 0.5) {
    planes.step([&](const sim::Snapshot& s) { on_planes = s.wall_contacts; });
    mesh.step([&](const sim::Snapshot& s) { on_mesh = s.wall_contacts; });
    if (on_planes == 2) ++both;
    if (on_mesh != on_planes) ++differ;  // a touch of a few nm, round-off apart
  }
  INFO("dt " << planes.dt() << " s, steps " << planes.stepCount() << ", on both faces " << both);
  CHECK(both > static_cast<int>(planes.stepCount() / 4));  // it rested on both faces for a while
  CHECK(differ < static_cast<int>(planes.stepCount() / 1000));
  const auto& xp = planes.particles().position[0];
  const auto& xm = mesh.particles().position[0];
  INFO("planes " << xp.transpose() << "  mesh " << xm.transpose());
  CHECK((xp - xm).norm() < 1e-9);
  CHECK((planes.particles().velocity[0] - mesh.particles().velocity[0]).norm() < 1e-8);
  CHECK((planes.particles().omega[0] - mesh.particles().omega[0]).norm() < 1e-6);
  // Settled in the crease at the height of two contacts each carrying m g / sqrt(2).
  CHECK(std::abs(xm.x()) < 1e-6);
  CHECK(xm.z() < r * std::sqrt(2.0));
  CHECK(xm.z() > r * std::sqrt(2.0) - 1e-4);
}

TEST_CASE("a ball pressed into a shallow concave mesh crease slides across it and keeps its energy",
          "[walls]") {
  // A frictionless, undamped ball squeezed 0.1 mm between a ceiling plane and a
  // valley of two faces at 176.25 degrees (a crease of a 96-facet concave),
  // shot across the crease: it rocks to and fro over it. The faces as one smooth
  // surface (the default smooth angle): the energy stays within the step's
  // bounded oscillation (2 % here, the same after ten times as long: the crease's
  // kink rocks the ball). Counted as two faces, the second touch switches on and
  // off with almost the first one's overlap each time the ball crosses the edge of
  // the wedge over the crease where both faces are nearest: energy is made, and
  // the watchdog stops the run, as it stopped the coarse bonded crusher run's jam.
  const double half = 0.5 * 3.75 * M_PI / 180.0, L = 0.02, W = 0.02, r = 4.15e-3, pressed = 1e-4;
  auto run = [&](double smooth_angle_deg) {
    sim::Wall valley = test::floorPlane();
    valley.name = "valley";
    valley.shape = sim::WallShape::Mesh;
    valley.mesh.vertices = {
        {-L, -W, L * std::tan(half)}, {-L, W, L * std::tan(half)}, {0, -W, 0}, {0, W, 0},
        {L, -W, L * std::tan(half)},  {L, W, L * std::tan(half)}};
    valley.mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
    valley.smooth_angle_deg = smooth_angle_deg;
    const double z = r - pressed;
    auto model = test::linearModel(1e6, 0.0, 0.0);
    model.walls = {valley, test::plane("ceiling", Vec3(0, 0, z + r - pressed), -Vec3::UnitZ())};
    sim::World world(model, {test::sphere(Vec3(0, 0.003, z), r, Vec3(2.0, 0, 0))}, 1);
    double first = -1, worst = 0, farthest = 0;
    while (world.time() < 0.01) {
      world.step([&](const sim::Snapshot& s) {
        const double e = s.energy.total();
        if (first < 0) first = e;
        worst = std::max(worst, std::abs(e - first) / first);
      });
      farthest = std::max(farthest, std::abs(world.particles().position[0].x()));
    }
    INFO("smooth angle " << smooth_angle_deg << " deg: energy " << first << " J, largest change "
                         << worst << " of it, farthest " << farthest * 1e3
                         << " mm from the crease");
    CHECK(farthest > 0.3e-3);  // beyond the wedge (0.27 mm wide) on both sides
    return worst;
  };
  CHECK(run(10.0) < 0.05);
  CHECK_THROWS_WITH(run(0.0), Catch::Contains("energy grew"));
}

TEST_CASE("a mesh wall's contact slots are saved and restored: a restart in a crease is bit for bit", "[walls][checkpoint]") {
  const auto model = grooveModel({grooveMesh()});
  // Saved at the first step after 0.1 s where the ball touches the mesh twice.
  sim::World first(model, {grooveBall()}, 1);
  sim::WorldState state;
  auto touchesTwice = [](const sim::WorldState& s) {
    return std::any_of(s.wall_history.begin(), s.wall_history.end(), [](const sim::WallHistory& h) { return h.slot > 0; });
  };
  do {
    first.step();
    state = first.exportState();
  } while (first.time() < 0.1 || !touchesTwice(state));
  const std::uint64_t steps = first.stepCount() + 5000;
  sim::World whole(model, {grooveBall()}, 1);
  while (whole.stepCount() < steps) whole.step();
  const auto path = std::filesystem::temp_directory_path() / "rocklab-mesh-slots.h5";
  sim::output::writeCheckpoint(path, state, "scene");
  auto cp = sim::output::readCheckpoint(path);
  std::filesystem::remove(path);
  sim::World second(model, std::move(cp.state), 1);
  while (second.stepCount() < steps) second.step();
  CHECK(second.stateHash() == whole.stateHash());
}

TEST_CASE("a removed gate releases the ball - a moving wall carries it", "[walls]") {
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

TEST_CASE("a rotating wall bats a ball at rest: first touch at the analytic angle, it leaves at twice the wall's speed",
          "[walls]") {
  // A square through the pivot (origin), normal +z at t = 0, turning about x at
  // omega: its normal is n(theta) = (0, -sin theta, cos theta), theta = omega t.
  // The ball (no gravity, frictionless, undamped) at c = (0, y0, z0) is touched
  // when c . n = r: rho cos(theta + phi) = r, rho = |(y0, z0)|, tan phi = y0 / z0.
  // Contact lasts pi sqrt(m / k) = 0.15 ms, in which the plane turns 1.5e-4 rad:
  // an elastic bounce off a wall whose surface moves at u = (omega x p) . n
  // normal to itself at the contact point p, so the ball leaves at 2 u along n.
  const double omega = 1.0, y0 = 0.1, z0 = 0.03, r = 0.01;
  auto model = test::linearModel(1e7);  // no friction, no damping, no gravity
  sim::Wall paddle;  // a square 0.4 m across: an infinite plane cannot rotate
  paddle.name = "paddle";
  paddle.shape = sim::WallShape::Polygon;
  paddle.vertices = {{-0.2, -0.2, 0}, {0.2, -0.2, 0}, {0.2, 0.2, 0}, {-0.2, 0.2, 0}};
  paddle.material = 1;
  paddle.motion.angular_velocity = Vec3(omega, 0, 0);
  model.walls.push_back(paddle);
  sim::World w(model, {test::sphere({0, y0, z0}, r)}, 1);
  const double rho = std::hypot(y0, z0), phi = std::atan2(y0, z0);
  const double theta = std::acos(r / rho) - phi, t_touch = theta / omega;
  while (w.particles().velocity[0].isZero(0) && w.time() < 1.0) w.step();
  // The first step that feels the wall: within a step of the touch (two: the
  // kick that first moves the ball is the one after the overlap appears).
  CHECK(w.time() >= t_touch);
  CHECK(w.time() <= t_touch + 2 * w.dt());
  const Vec3 n(0, -std::sin(theta), std::cos(theta));
  const Vec3 c(0, y0, z0), contact = c - r * n;
  const double u = Vec3(omega, 0, 0).cross(contact).dot(n);
  while (w.time() < t_touch + 0.02) w.step();
  const Vec3 v = w.particles().velocity[0];
  INFO("v " << v.transpose() << ", expected " << (2 * u * n).transpose());
  // 1 %: the leapfrog's own impact error at this step (tests/stability:
  // leapfrogImpactError, <= 0.3 % at omega dt = 0.45) plus the turn during contact.
  CHECK(v.norm() == Approx(2 * u).epsilon(0.01));
  CHECK(v.normalized().dot(n) > std::cos(0.01));
}

TEST_CASE("a wall that appears later (active_from): passed through before, bounced off after", "[walls]") {
  // A square in the plane x = 0 becomes active at t = 0.2 s. Ball A (1 m/s along
  // x) crosses it at t = 0.1 s and is 0.1 m past it when it appears; ball B, on a
  // parallel track, arrives at t = 0.34 s and bounces back (undamped, frictionless).
  auto model = test::linearModel(1e7);
  sim::Wall gate;
  gate.name = "gate";
  gate.shape = sim::WallShape::Polygon;
  gate.vertices = {{0, -0.05, -0.05}, {0, 0.05, -0.05}, {0, 0.05, 0.05}, {0, -0.05, 0.05}};
  gate.material = 1;
  gate.active_from = 0.2;
  model.walls.push_back(gate);
  sim::World w(model, {test::sphere({-0.1, 0, 0}, 0.01, {1, 0, 0}), test::sphere({-0.35, 0.03, 0}, 0.01, {1, 0, 0})},
               1);
  while (w.time() < 0.5) w.step();
  const auto& p = w.particles();
  CHECK(p.velocity[0] == Vec3(1, 0, 0));  // never touched
  CHECK(p.position[0].x() == Approx(-0.1 + w.time()).margin(1e-12));
  // 2 %: the leapfrog's impact error at the automatic step (<= 1.3 %, tests/stability).
  CHECK(p.velocity[1].x() == Approx(-1.0).epsilon(0.02));
  CHECK(p.position[1].x() < -0.1);
}

TEST_CASE("a wall that only spins moves its material, not its surface: it drags a resting ball", "[walls]") {
  // A square mesh floor spinning at 0.002 rad/s about a vertical axis 100 m away
  // (WallMotion spin: a surface that maps onto itself, like the crusher's mantle):
  // near the ball its material moves at -0.2 m/s along x, almost uniformly. The
  // surface stays put (no neighbour rebuild, no pose), but the wall is not static:
  // the ball is dragged to 2/7 of the belt speed as by a translating floor.
  sim::Wall floor = test::floorPlane();
  floor.shape = sim::WallShape::Mesh;
  floor.mesh.vertices = {{-0.2, -0.2, 0}, {0.2, -0.2, 0}, {0.2, 0.2, 0}, {-0.2, 0.2, 0}};
  floor.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  floor.motion.spin_rate = 0.002;
  floor.motion.spin_axis = Vec3::UnitZ();
  floor.motion.spin_point = Vec3(0, -100, 0);
  REQUIRE(!floor.motion.isStatic());
  REQUIRE(!floor.motion.surfaceMoves());

  sim::detail::WallRuntime runtime;
  runtime.setup(floor);
  runtime.update(floor, 0.0);
  runtime.setReference();
  runtime.update(floor, 50.0);
  CHECK(runtime.displacementSinceReference() == 0.0);
  CHECK((runtime.velocityAt(Vec3(0, 0, 0)) - Vec3(-0.2, 0, 0)).norm() < 1e-12);
  CHECK(runtime.velocityAt(Vec3(0, -100, 0.3)).norm() < 1e-12);  // on the spin axis

  auto model = test::linearModel(2e7, 0.5, 0.3);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls.push_back(floor);
  sim::World w(model, {test::sphere({0, 0, 0.00999}, 0.01)}, 1);
  while (w.time() < 0.3) w.step();
  CHECK(w.particles().velocity[0].x() == Approx(2.0 / 7.0 * -0.2).epsilon(0.02));
  CHECK(std::abs(w.particles().velocity[0].y()) < 1e-3);
  CHECK(w.particles().position[0].z() == Approx(0.01).margin(2e-4));
}

TEST_CASE("a spinning faceted frustum wall: the contact velocity has no spin normal part, its tangential part is omega x r",
          "[walls][motion]") {
  // A coarse (12-facet) mantle spinning about its axis and translating: on a facet
  // off its middle omega x r leans into the facet (the true surface of revolution
  // would see a purely tangential velocity). The contact velocity keeps the
  // translation in full and only the tangential part of the spin.
  geometry::FrustumSpec spec;
  spec.bottom_centre = Vec3(0, 0, 0);
  spec.top_centre = Vec3(0, 0, 0.1);
  spec.bottom_radius = 0.15;
  spec.top_radius = 0.05;
  spec.segments = 12;
  sim::Wall mantle;
  mantle.shape = sim::WallShape::Mesh;
  mantle.mesh = geometry::frustumMesh(spec);
  const double spin = 30.0;  // rad/s
  const Vec3 drift(0.02, 0.0, 0.01);
  mantle.motion.spin_rate = spin;
  mantle.motion.spin_axis = Vec3::UnitZ();
  mantle.motion.velocity = drift;

  sim::detail::WallRuntime runtime;
  runtime.setup(mantle);
  runtime.update(mantle, 0.0);
  int checked = 0;
  for (double azimuth : {0.05, 0.2, 0.4, 1.1, 2.9}) {  // rad: facets span 0.52 rad
    const double r = 0.01;
    // A ball centre just outside the surface at mid-height (radius 0.1 there).
    const Vec3 radial(std::cos(azimuth), std::sin(azimuth), 0.0);
    const Vec3 centre = Vec3(0, 0, 0.05) + (0.1 + 0.7 * r) * radial;
    std::array<sim::detail::WallContact, 1> nearest;
    std::vector<std::uint32_t> triangles;
    std::vector<double> distances;
    REQUIRE(runtime.near(mantle, centre, r, triangles, distances));
    REQUIRE(runtime.meshTouches(centre, r, triangles, nearest) == 1);
    const sim::detail::WallContact& touch = nearest[0];
    const Vec3 n = touch.normal;
    const Vec3 point = centre + (r - touch.overlap) * n;
    const Vec3 omega_x_r = spin * Vec3::UnitZ().cross(point);
    const Vec3 v = runtime.contactVelocityAt(point, n);
    CHECK(std::abs((v - drift).dot(n)) < 1e-12);  // no spin along the normal
    CHECK(((v - drift) - (omega_x_r - omega_x_r.dot(n) * n)).norm() < 1e-12);  // tangential part of omega x r
    CHECK((runtime.velocityAt(point) - drift - omega_x_r).norm() < 1e-12);  // the material's velocity is unchanged
    // The facet's normal part that is removed: up to omega R sin(pi/12) at an edge.
    if (std::abs(omega_x_r.dot(n)) > 0.05 * spin * 0.1 * std::sin(M_PI / 12)) ++checked;
  }
  CHECK(checked >= 3);  // the faceting really gives the spin a normal part here
}

TEST_CASE("the friction rule picks the smaller, the larger or the mean of the two materials", "[walls]") {
  // A ball sliding on the floor without spin decelerates at mu g until it rolls
  // (at t = 2 v0 / (7 mu g), 48 ms for mu = 0.605): measured at 20 ms.
  const auto slide = [](sim::FrictionRule rule) {
    auto model = test::linearModel(2e7, 0.0, 0.2);
    model.materials[0].friction = 0.37;   // ball
    model.materials[1].friction = 0.605;  // floor
    model.contact.friction_rule = rule;
    model.gravity = Vec3(0, 0, -9.81);
    sim::Wall floor = test::floorPlane();
    floor.material = 1;
    model.walls.push_back(floor);
    // Resting on the floor under its own weight: centre at r minus the static overlap m g / kn.
    const double r = 0.01, m = 2730.0 * 4.0 / 3.0 * M_PI * r * r * r;
    sim::World w(model, {test::sphere(Vec3(0, 0, r - m * 9.81 / 1e7), r, {1.0, 0, 0})}, 1);
    const double t = 0.02;
    while (w.time() < t) w.step();
    return (1.0 - w.particles().velocity[0].x()) / (9.81 * w.time());  // the mu it slid with
  };
  CHECK(slide(sim::FrictionRule::Min) == Approx(0.37).epsilon(0.02));  // Eq 2-39, the default
  CHECK(slide(sim::FrictionRule::Max) == Approx(0.605).epsilon(0.02));
  CHECK(slide(sim::FrictionRule::Mean) == Approx(0.4875).epsilon(0.02));
}
