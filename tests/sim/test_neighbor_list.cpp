// The neighbour grid (sim/src/neighbor_list.h) against brute force.
#include <catch2/catch.hpp>

#include <algorithm>

#include "neighbor_list.h"
#include "rocklab/geometry/packing.h"
#include "support.h"

using namespace rocklab;
using test::Vec3;

TEST_CASE("neighbour grid finds exactly the brute-force pairs at a 7:1 size ratio", "[walls][neighbours]") {
  geometry::Rng rng(9);
  std::vector<double> radii;
  for (int k = 0; k < 1500; ++k) radii.push_back(k % 10 == 0 ? 0.014 : rng.uniform(0.002, 0.004));
  const auto pos = geometry::randomNonOverlapping(radii, Vec3::Zero(), Vec3(0.25, 0.25, 0.25), {}, rng);
  REQUIRE(pos.size() == radii.size());
  const double skin = 0.006;
  sim::detail::NeighborFinder finder;
  sim::detail::PairList list;
  for (int threads : {1, 2}) {
    finder.build(pos, radii, skin, threads, list);
    std::size_t expected = 0, found = 0;
    for (std::size_t i = 0; i < pos.size(); ++i)
      for (std::size_t j = i + 1; j < pos.size(); ++j)
        if ((pos[i] - pos[j]).norm() < radii[i] + radii[j] + skin) {
          ++expected;
          const auto b = list.partner.begin() + list.row_offset[i], e = list.partner.begin() + list.row_offset[i + 1];
          found += std::binary_search(b, e, static_cast<std::uint32_t>(j));
        }
    CHECK(list.size() == expected);
    CHECK(found == expected);
    CHECK(expected > 500);
  }
}
