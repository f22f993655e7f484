#include <catch2/catch.hpp>

#include "rocklab/geometry/packing.h"

using namespace rocklab::geometry;

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
