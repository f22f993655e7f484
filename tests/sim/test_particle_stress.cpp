// Particle stress tensor and octahedral shear stress (dem-models.md §11).
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "rocklab/sim/particle_stress.h"
#include "sim/support.h"

using namespace rocklab;
using geometry::Mat3;
using geometry::Vec3;

TEST_CASE("particle stress: a sphere between two platens gives q = (2 sqrt 2 / pi) F/d^2 (Eq 6-12)",
          "[stress]") {
  // A sphere pressed by two walls along z (tiny overlap: the contact points are
  // almost at the poles), at rest, no gravity: two opposite point forces F.
  const double r = 0.01, overlap = 1e-7;
  sim::Model model = test::linearModel(1e6);
  model.walls = {test::plane("bottom", Vec3(0, 0, -r + overlap), Vec3::UnitZ()),
                 test::plane("top", Vec3(0, 0, r - overlap), -Vec3::UnitZ())};
  sim::World world(model, {test::sphere(Vec3::Zero(), r)}, 1);
  world.step();
  const std::vector<Mat3> stress = world.particleStress();
  REQUIRE(stress.size() == 1);
  // Series springs ball-wall: k = kn kn / (kn + kn) = kn / 2 (Eq 2-20).
  const double force = 0.5e6 * overlap, d = 2 * r;
  const sim::PrincipalStresses s = sim::principalStresses(stress[0]);
  const double volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  CHECK(s.major ==
        Approx(2 * force * (r - overlap / 2) / volume).epsilon(1e-9));  // compression positive
  CHECK(std::abs(s.intermediate) < 1e-12 * s.major);
  CHECK(std::abs(s.minor) < 1e-12 * s.major);
  const double q = sim::octahedralShearStress(s);
  CHECK(q / (force / (d * d)) ==
        Approx(2 * std::sqrt(2.0) / std::numbers::pi).epsilon(1e-5));  // 0.9003
  CHECK(std::abs(s.minor_direction.z()) <
        1e-9);  // the least compressive direction is in the xy plane
}

TEST_CASE("particle stress and wall loads of a world not stepped yet are zero (its contact lists come with the first step)",
          "[stress]") {
  // The crusher's breakage check may look before the first step.
  const double r = 0.01;
  sim::Model model = test::linearModel(1e6);
  model.walls = {test::plane("bottom", Vec3(0, 0, -r + 1e-6), Vec3::UnitZ())};
  const sim::World world(model, {test::sphere(Vec3::Zero(), r), test::sphere(Vec3(0.019, 0, 0), r)}, 1);
  const std::vector<Mat3> stress = world.particleStress();
  REQUIRE(stress.size() == 2);
  CHECK(stress[0] == Mat3::Zero());
  CHECK(world.wallForces()[0] == Vec3::Zero());
}

TEST_CASE("wall load: a moving platen's load is read where the platen is now, not a step ago",
          "[stress][walls]") {
  // A ball too heavy to move; a plane closing on it at v. Its load after a step
  // is the series spring kn / 2 (Eq 2-20) times the overlap at the current time,
  // v t - gap. Read against the platen's pose of the step before, it would be
  // short by kn / 2 v dt, which the bound is a thousandth of.
  const double r = 0.01, gap = 1e-6, v = 0.05, kn = 1e6;
  sim::Model model = test::linearModel(kn);
  model.materials[0].density = 1e15;
  model.timestep.dt = 1e-6;  // s: the heavy ball alone would allow seconds
  sim::Wall top = test::plane("top", Vec3(0, 0, r + gap), -Vec3::UnitZ());
  top.motion.velocity = Vec3(0, 0, -v);
  model.walls = {top};
  sim::World world(model, {test::sphere(Vec3::Zero(), r)}, 1);
  const double dt = world.dt();
  int loaded = 0;
  while (world.time() < 4 * gap / v) {
    world.step();
    const double overlap = v * world.time() - gap;
    if (overlap <= v * dt) continue;  // the contact appears at the next force pass
    const double load = world.wallForces()[0].z();
    CHECK(std::abs(load - 0.5 * kn * overlap) < 1e-3 * 0.5 * kn * v * dt);
    ++loaded;
  }
  CHECK(loaded > 10);
  CHECK(world.particles().position[0].norm() < 1e-12);  // the ball did not move
  // The platen's work on the ball: the integral of load x speed, kn / 4 (v t - gap)^2
  // (each step counts the load of its force pass: to within one step's share).
  const double reach = v * world.time() - gap;
  CHECK(std::abs(world.movingWallWork() - 0.25 * kn * reach * reach) < 0.5 * kn * reach * v * dt);
  // A World rebuilt from the exported state goes on counting from the same total.
  const sim::World rebuilt(model, world.exportState(), 1);
  CHECK(rebuilt.movingWallWork() == world.movingWallWork());
}

TEST_CASE("particle stress: equal principal stresses give q = 0 - q is invariant under rotation",
          "[stress]") {
  const sim::PrincipalStresses iso = sim::principalStresses(Mat3::Identity() * 5e6);
  CHECK(sim::octahedralShearStress(iso) == Approx(0.0).margin(1e-6));
  Mat3 m;
  m << 3, 1, 0, 1, 2, 0.5, 0, 0.5, 1;
  const Mat3 rot = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const double q = sim::octahedralShearStress(sim::principalStresses(m));
  CHECK(sim::octahedralShearStress(sim::principalStresses(rot * m * rot.transpose())) == Approx(q));
  const sim::PrincipalStresses s = sim::principalStresses(m);
  CHECK(s.major >= s.intermediate);
  CHECK(s.intermediate >= s.minor);
  CHECK((m * s.minor_direction - s.minor * s.minor_direction).norm() < 1e-12);
}

TEST_CASE("bonded clusters: fragments are the balls joined by intact bonds", "[stress][bonds]") {
  sim::BondState b;
  auto add = [&](std::uint32_t a, std::uint32_t c, bool intact) {
    b.a.push_back(a);
    b.b.push_back(c);
    b.intact.push_back(intact ? 1 : 0);
  };
  add(0, 1, true);
  add(1, 4, true);
  add(2, 3, true);
  add(3, 5, false);  // broken: 5 is on its own
  add(6, 2, true);
  CHECK(sim::bondedClusters(7, b) == std::vector<std::uint32_t>{0, 0, 1, 1, 0, 2, 1});
}
