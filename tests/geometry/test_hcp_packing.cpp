#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "rocklab/geometry/bond_pairs.h"
#include "rocklab/geometry/hcp_packing.h"
#include "rocklab/geometry/structure_statistics.h"

using namespace rocklab::geometry;

namespace {

std::vector<std::vector<std::size_t>> neighbours(const std::vector<Sphere>& s, double gap) {
  std::vector<std::vector<std::size_t>> n(s.size());
  for (const auto& [a, b] : bondPairs(s, gap)) {
    n[a].push_back(b);
    n[b].push_back(a);
  }
  return n;
}

}  // namespace

TEST_CASE("hcp: every interior sphere touches 12, stacked A-B-A-B (mirror above and below)",
          "[geometry]") {
  const double r = 2.5e-3, D = 42e-3;
  const auto s = hcpPacking(r, D, 0.0);
  REQUIRE(s.size() > 300);
  const auto n = neighbours(s, 1e-9);
  std::size_t interior = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i].centre.norm() + 3 * r > 0.5 * D) continue;  // its neighbours are all inside
    ++interior;
    REQUIRE(n[i].size() == 12);
    // HCP, not FCC: every neighbour above (y > 0) has its mirror image below.
    for (std::size_t j : n[i]) {
      const Vec3 d = s[j].centre - s[i].centre;
      CHECK(std::abs(d.norm() - 2 * r) < 1e-12 * r);
      const Vec3 mirror(d.x(), -d.y(), d.z());
      bool found = false;
      for (std::size_t k : n[i]) found |= ((s[k].centre - s[i].centre) - mirror).norm() < 1e-9 * r;
      CHECK(found);
    }
  }
  CHECK(interior > 50);
  const StructureStatistics st = structureStatistics(s, std::numbers::pi * D * D * D / 6, 1e-9);
  CHECK(st.max_overlap < 1e-12 * r);
  // The boundary adds void: only spheres wholly inside the 42 mm sphere (R = 8.4 r).
  CHECK(st.porosity > kHcpPorosity + 0.1);
  CHECK(st.porosity < 0.5);
}

TEST_CASE("hcp: the interior density approaches the lattice's 1 - 0.2595", "[geometry]") {
  const double r = 1.0;
  const auto s = hcpPacking(r, 70.0, 0.0);
  auto density = [&](double probe) {
    std::size_t inside = 0;
    for (const Sphere& b : s) inside += b.centre.norm() < probe;
    return inside * std::pow(r / probe, 3.0);
  };
  const double err_small = std::abs(density(8.0) - (1 - kHcpPorosity));
  const double err_large = std::abs(density(30.0) - (1 - kHcpPorosity));
  CHECK(err_large < 0.01);
  CHECK(err_large < err_small);
}

TEST_CASE("hcp: rotation about z turns the stacking axis in the x-y plane", "[geometry]") {
  const double r = 1.0, D = 20.0;
  const auto s0 = hcpPacking(r, D, 0.0);
  const auto s30 = hcpPacking(r, D, 30.0);
  const auto s90 = hcpPacking(r, D, 90.0);
  REQUIRE(s30.size() == s0.size());
  const Mat3 turn = Eigen::AngleAxisd(std::numbers::pi / 6, Vec3::UnitZ()).toRotationMatrix();
  for (std::size_t i = 0; i < s0.size(); ++i)
    CHECK((s30[i].centre - turn * s0[i].centre).norm() < 1e-12);
  // At 90° the layers are normal to x: every x is a multiple of the layer spacing.
  const double layer = 2 * r * std::sqrt(2.0 / 3.0);
  for (const Sphere& b : s90)
    CHECK(std::abs(b.centre.x() / layer - std::round(b.centre.x() / layer)) < 1e-9);
  CHECK_THROWS_WITH(hcpPacking(r, D, 91.0),
                    Catch::Contains("angle = 91") && Catch::Contains("[0, 90]"));
  CHECK_THROWS_WITH(hcpPacking(r, 1.0, 0.0), Catch::Contains("diameter = 1"));
}
