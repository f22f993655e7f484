#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "rocklab/geometry/bond_pairs.h"
#include "rocklab/geometry/random_pack.h"
#include "rocklab/geometry/structure_statistics.h"

using namespace rocklab::geometry;

TEST_CASE("bond pairs: handcrafted set, the gap rule uses the smaller radius", "[geometry]") {
  const std::vector<Sphere> s{
      {Vec3(0, 0, 0), 1.0},         // 0
      {Vec3(2, 0, 0), 1.0},         // 1 touches 0
      {Vec3(0, 2.0005, 0), 1.0},    // 2 gap 5e-4 to 0: within 1e-3 x 1
      {Vec3(5, 0, 0), 1.0},         // 3 gap 1 to 1: no bond
      {Vec3(0, -1.5, 0), 1.0},      // 4 overlaps 0 by 0.5: a bond
      {Vec3(0, 0, -1.10015), 0.1},  // 5 gap 1.5e-4 to 0: above 1e-3 x 0.1
      {Vec3(0, 0, 1.10005), 0.1},   // 6 gap 5e-5 to 0: within
  };
  const std::vector<SpherePair> expected{{0, 1}, {0, 2}, {0, 4}, {0, 6}};
  CHECK(bondPairs(s, 1e-3) == expected);
  CHECK(bondPairs(s, 0.0) == std::vector<SpherePair>{{0, 1}, {0, 4}});
  CHECK_THROWS_WITH(bondPairs(s, -0.1),
                    Catch::Contains("gap_tolerance = -0.1") && Catch::Contains(">= 0"));
  const StructureStatistics st = structureStatistics(s, 100.0, 1e-3);
  CHECK(st.contact_count == 4);
  CHECK(st.coordination_number == Approx(8.0 / 7.0));
  CHECK(st.overlapping_pairs == 1);
  CHECK(st.max_overlap == Approx(0.5));
  CHECK(st.max_overlap_fraction == Approx(0.5));
}

TEST_CASE("bond pairs: the grid finds what a brute-force search finds", "[geometry]") {
  std::vector<Sphere> s = relaxedRandomPack(300, 1.0, 8.0, 3, 200).spheres;
  Rng rng(4);
  for (Sphere& b : s) b.radius *= rng.uniform(0.9, 1.0);  // polydisperse, some gaps
  std::vector<SpherePair> brute;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j)
      if (withinBondGap(s[i], s[j], 0.05)) brute.emplace_back(i, j);
  REQUIRE(brute.size() > 100);
  CHECK(bondPairs(s, 0.05) == brute);
}

TEST_CASE("structure statistics: lens volumes and porosity", "[geometry]") {
  // Two unit spheres at distance d overlap in a lens of π (4 + d)(2 − d)² / 12.
  const Sphere a{Vec3::Zero(), 1.0}, b{Vec3(1, 0, 0), 1.0};
  CHECK(lensVolume(a, b) == Approx(std::numbers::pi * 5.0 / 12.0));
  CHECK(lensVolume(a, Sphere{Vec3(0.2, 0, 0), 0.5}) ==
        Approx(4.0 / 3.0 * std::numbers::pi * 0.125));  // inside
  CHECK(lensVolume(a, Sphere{Vec3(3, 0, 0), 1.0}) == 0.0);
  const double ball = 4.0 / 3.0 * std::numbers::pi;
  const StructureStatistics st = structureStatistics({a, b}, 4 * ball, 0.0);
  CHECK(st.solid_volume == Approx(2 * ball - std::numbers::pi * 5.0 / 12.0));
  CHECK(st.porosity == Approx(1 - st.solid_volume / (4 * ball)));
  CHECK_THROWS_WITH(structureStatistics({a}, 0.0, 0.0), Catch::Contains("envelope_volume = 0"));
}
