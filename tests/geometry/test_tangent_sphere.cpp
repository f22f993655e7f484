#include <catch2/catch.hpp>
#include <cmath>

#include "rocklab/geometry/tangent_sphere.h"

using namespace rocklab::geometry;

namespace {

std::array<Sphere, 4> regularTetrahedron(double edge, double radius) {
  // Alternate corners of a cube of side edge/√2: every pair at distance `edge`.
  const double h = edge / std::sqrt(2.0) / 2;
  return {Sphere{Vec3(h, h, h), radius}, Sphere{Vec3(h, -h, -h), radius},
          Sphere{Vec3(-h, h, -h), radius}, Sphere{Vec3(-h, -h, h), radius}};
}

double worstTangencyResidual(const std::array<Sphere, 4>& group, const Sphere& s) {
  double worst = 0;
  for (const Sphere& g : group)
    worst = std::max(worst, std::abs((s.centre - g.centre).norm() - (s.radius + g.radius)) /
                                (s.radius + g.radius));
  return worst;
}

}  // namespace

TEST_CASE("tangent sphere: regular tetrahedron of touching spheres", "[geometry]") {
  const auto group = regularTetrahedron(1.0, 0.5);
  const TangentSolution s = innerTangentSphere(group);
  REQUIRE(s.sphere);
  CHECK(s.failure == TangentFailure::None);
  CHECK(s.sphere->radius == Approx(std::sqrt(6.0) / 4 - 0.5).epsilon(1e-13));
  CHECK(s.sphere->centre.norm() < 1e-14);
}

TEST_CASE("tangent sphere: random groups are tangent to all four to 1e-12", "[geometry]") {
  Rng rng(20);
  int solved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::array<Sphere, 4> group = regularTetrahedron(1.0, 0.5);
    for (Sphere& g : group) {
      g.centre += Vec3(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1));
      g.centre += Vec3(3.7, -1.2, 250.0);  // far from the origin: the solve must not cancel
      g.radius = rng.uniform(0.3, 0.5);
    }
    const TangentSolution s = innerTangentSphere(group);
    if (!s.sphere) continue;
    ++solved;
    CHECK(worstTangencyResidual(group, *s.sphere) < 1e-12);
    CHECK(s.sphere->radius > 0);
  }
  CHECK(solved > 190);  // these groups all leave a void
}

TEST_CASE("tangent sphere: unequal radii", "[geometry]") {
  std::array<Sphere, 4> group = regularTetrahedron(1.0, 0.45);
  group[0].radius = 0.2;
  const TangentSolution s = innerTangentSphere(group);
  REQUIRE(s.sphere);
  CHECK(worstTangencyResidual(group, *s.sphere) < 1e-12);
  // The small sphere leaves more room on its side: the centre moves from the
  // centroid (the origin) towards it.
  CHECK(s.sphere->centre.dot(group[0].centre) > 0);
  CHECK(s.sphere->radius > std::sqrt(6.0) / 4 - 0.45);  // larger than with four equal spheres
}

TEST_CASE("tangent sphere: coplanar and nearly coplanar groups are degenerate", "[geometry]") {
  const std::array<Sphere, 4> flat{Sphere{Vec3(0, 0, 0), 0.3}, Sphere{Vec3(1, 0, 0), 0.3},
                                   Sphere{Vec3(0, 1, 0), 0.3}, Sphere{Vec3(1, 1, 0), 0.3}};
  CHECK(innerTangentSphere(flat).failure == TangentFailure::Degenerate);
  CHECK_FALSE(innerTangentSphere(flat).sphere);
  std::array<Sphere, 4> nearly = flat;
  nearly[3].centre.z() = 1e-11;
  CHECK(innerTangentSphere(nearly).failure == TangentFailure::Degenerate);
  nearly[3].centre.z() = 1e-3;  // flat but a real tetrahedron: solvable, centre outside
  CHECK(innerTangentSphere(nearly).failure != TangentFailure::Degenerate);
}

TEST_CASE("tangent sphere: no positive root, centre outside, bad input", "[geometry]") {
  // Heavily overlapping spheres: the circumradius (0.612) is below the radius.
  CHECK(innerTangentSphere(regularTetrahedron(1.0, 0.7)).failure == TangentFailure::NoPositiveRoot);
  // A flat corner tetrahedron: the circumcentre (0.5, 0.5, 0.05) lies outside it.
  const std::array<Sphere, 4> corner{Sphere{Vec3(0, 0, 0), 0.01}, Sphere{Vec3(1, 0, 0), 0.01},
                                     Sphere{Vec3(0, 1, 0), 0.01}, Sphere{Vec3(0, 0, 0.1), 0.01}};
  CHECK(innerTangentSphere(corner).failure == TangentFailure::CentreOutside);
  std::array<Sphere, 4> bad = regularTetrahedron(1.0, 0.5);
  bad[2].radius = -1;
  CHECK_THROWS_WITH(innerTangentSphere(bad),
                    Catch::Contains("radius of sphere 3") && Catch::Contains("must be > 0"));
}
