#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "grow_to_fit.h"  // geometry/src: the grow-and-push step on its own
#include "rocklab/geometry/agglomerate_packing.h"
#include "rocklab/geometry/bond_pairs.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/random_pack.h"

using namespace rocklab::geometry;

namespace {

VoidFillParams smallParams(double r0) {
  VoidFillParams p;
  p.r_max = 1.0;
  p.r0 = r0;
  p.agglomerate_radius = 6.0;
  p.gap_tolerance = 1e-3;
  p.seed = 7;
  return p;
}

std::vector<Sphere> smallPack() {
  return relaxedRandomPack(115, 1.0, 6.0, 11).spheres;
}

std::vector<int> contactsPerSphere(const std::vector<Sphere>& s, double gap) {
  std::vector<int> c(s.size(), 0);
  for (const auto& [a, b] : bondPairs(s, gap)) ++c[a], ++c[b];
  return c;
}

}  // namespace

TEST_CASE("random pack: converges without overlaps, inside the container, seeded", "[geometry]") {
  const RandomPackResult a = relaxedRandomPack(115, 1.0, 6.0, 11);
  const RandomPackResult b = relaxedRandomPack(115, 1.0, 6.0, 11);
  REQUIRE(a.spheres.size() == 115);
  CHECK(a.max_overlap == 0);
  for (std::size_t i = 0; i < a.spheres.size(); ++i) {
    CHECK(a.spheres[i].centre == b.spheres[i].centre);
    CHECK(a.spheres[i].centre.norm() <= 5.0 + 1e-6);
  }
  const auto c = bondPairs(a.spheres, 0.0);
  CHECK(c.empty() == false);  // dense enough that spheres touch
  for (const auto& [i, j] : c) CHECK(-sphereGap(a.spheres[i], a.spheres[j]) <= 1e-6);
}

TEST_CASE(
    "grow to fit: grows off-centre in a tetrahedral void to the tangent size with 3+ contacts",
    "[geometry]") {
  // Four touching unit spheres (edge 2): the void's tangent sphere has r = √6/2 − 1.
  const double h = 2.0 / std::sqrt(2.0) / 2;
  SphereHashGrid grid{2.0 * 1.001, {}};
  for (const Vec3& c : {Vec3(h, h, h), Vec3(h, -h, -h), Vec3(-h, h, -h), Vec3(-h, -h, h)})
    grid.insert({c, 1.0});
  detail::GrowSettings g;
  g.r_start = 0.1;
  g.r_cap = 1.0;
  g.gap_tolerance = 1e-3;
  g.bound_radius = 10;
  const auto grown = detail::growToFit(Vec3(0.08, -0.03, 0.02), grid, g);
  REQUIRE(grown);
  const double tangent = std::sqrt(6.0) / 2 - 1;
  CHECK(grown->radius <= tangent * (1 + 1e-3));
  CHECK(grown->radius > 0.9 * tangent);
  CHECK_FALSE(detail::overlapsAny(*grown, grid));
  int contacts = 0;
  grid.forEachNear(grown->centre, [&](const SphereHashGrid::Entry& e) {
    contacts += withinBondGap(*grown, e.sphere, 1e-3);
  });
  CHECK(contacts >= 3);
  // Concentric with a fixed sphere: nothing to push along, rejected.
  CHECK_FALSE(detail::growToFit(Vec3(h, h, h), grid, g));
}

TEST_CASE("void filling: sizes in [r_min, r_max], inside, no overlaps, every added sphere bonded",
          "[geometry]") {
  const auto pack = smallPack();
  const VoidFillParams p = smallParams(3.0);
  const VoidFillResult out = fillVoids(pack, p);
  const VoidFillReport& r = out.report;
  REQUIRE(r.added > 50);
  CHECK(out.spheres.size() == pack.size() - r.input_dropped + r.added);
  CHECK(r.added == r.placed_tangent + r.placed_grown);
  CHECK(r.placed_grown > 0);
  CHECK(r.cells_tried == r.added + r.rejected_degenerate + r.rejected_no_root +
                             r.rejected_centre_outside + r.rejected_too_small +
                             r.rejected_outside_agglomerate + r.rejected_cannot_fit);
  CHECK(r.passes >= 2);
  for (std::size_t i = pack.size() - r.input_dropped; i < out.spheres.size(); ++i) {
    const Sphere& s = out.spheres[i];
    CHECK(s.radius >= p.r_max / p.r0);
    CHECK(s.radius <= p.r_max);
    CHECK(s.centre.norm() + s.radius <= p.agglomerate_radius * (1 + 1e-6));
  }
  CHECK(r.structure.max_overlap_fraction <= 1.01e-6);
  const auto contacts = contactsPerSphere(out.spheres, p.gap_tolerance);
  for (std::size_t i = pack.size() - r.input_dropped; i < out.spheres.size(); ++i)
    CHECK(contacts[i] >= 1);
  // Filling lowers the porosity of the loose pack and raises its coordination.
  const StructureStatistics before =
      structureStatistics(pack, 4.0 / 3.0 * std::numbers::pi * 216.0, 1e-3);
  CHECK(r.structure.porosity < before.porosity - 0.03);
  CHECK(r.structure.coordination_number > before.coordination_number);
}

TEST_CASE("void filling: deterministic for a seed, another seed another agglomerate",
          "[geometry]") {
  const auto pack = smallPack();
  VoidFillParams p = smallParams(2.0);
  const VoidFillResult a = fillVoids(pack, p), b = fillVoids(pack, p);
  REQUIRE(a.spheres.size() == b.spheres.size());
  for (std::size_t i = 0; i < a.spheres.size(); ++i) {
    CHECK(a.spheres[i].centre == b.spheres[i].centre);
    CHECK(a.spheres[i].radius == b.spheres[i].radius);
  }
  p.seed = 8;
  const VoidFillResult c = fillVoids(pack, p);
  bool differs = c.spheres.size() != a.spheres.size();
  for (std::size_t i = 0; !differs && i < a.spheres.size(); ++i)
    differs = c.spheres[i].centre != a.spheres[i].centre;
  CHECK(differs);
}

TEST_CASE("void filling: an FCC lattice gets one sphere of (sqrt 2 - 1) r in each octahedral void",
          "[geometry]") {
  // Touching unit spheres, cell 2√2. For r0 = 3 (r_min = 1/3) the octahedral voids
  // (√2 − 1 = 0.414) fill and the tetrahedral ones (0.225) do not.
  const double cell = 2 * std::sqrt(2.0);
  std::vector<Sphere> lattice;
  for (const Vec3& c : latticePoints(LatticeKind::FaceCentred, cell, Vec3::Zero(),
                                     Vec3::Constant(-3 * cell), {6, 6, 6}))
    lattice.push_back({c, 1.0});
  VoidFillParams p = smallParams(3.0);
  p.agglomerate_radius = 7.0;
  const VoidFillResult out = fillVoids(lattice, p);
  REQUIRE(out.report.added > 20);
  const std::size_t kept = lattice.size() - out.report.input_dropped;
  const auto contacts = contactsPerSphere(out.spheres, 1e-6);
  std::size_t octahedral = 0;
  for (std::size_t i = kept; i < out.spheres.size(); ++i) {
    const Sphere& s = out.spheres[i];
    if (std::abs(s.radius - (std::sqrt(2.0) - 1)) > 1e-9)
      continue;  // grown spheres at the boundary
    ++octahedral;
    // Its six neighbours (√2 away) are kept when they lie wholly inside the bound.
    if (s.centre.norm() + std::sqrt(2.0) + 1.0 <= p.agglomerate_radius) CHECK(contacts[i] == 6);
    CHECK(contacts[i] >= 3);
    // At an octahedral site: a cell corner shifted by half a cell along one axis.
    const Vec3 q = (s.centre / (0.5 * cell)).array().round();
    CHECK((s.centre - 0.5 * cell * q).norm() < 1e-9);
    CHECK(static_cast<long>(std::abs(q.sum())) % 2 == 1);
  }
  CHECK(octahedral > 0.9 * out.report.added);
}

TEST_CASE("void filling: parameter errors name the parameter, its value and the range",
          "[geometry]") {
  const std::vector<Sphere> pack{{Vec3::Zero(), 1.0}};
  VoidFillParams p = smallParams(0.5);
  CHECK_THROWS_WITH(fillVoids(pack, p),
                    Catch::Contains("r0 = 0.5") && Catch::Contains("must be >= 1"));
  p = smallParams(2.0);
  p.agglomerate_radius = 0.5;
  CHECK_THROWS_WITH(fillVoids(pack, p),
                    Catch::Contains("agglomerate_radius = 0.5") && Catch::Contains(">= r_max"));
  p = smallParams(2.0);
  p.gap_tolerance = -1;
  CHECK_THROWS_WITH(fillVoids(pack, p), Catch::Contains("gap_tolerance = -1"));
  p = smallParams(2.0);
  CHECK_THROWS_WITH(fillVoids({{Vec3::Zero(), 0.0}}, p),
                    Catch::Contains("radius of pack sphere 0 = 0"));
}
