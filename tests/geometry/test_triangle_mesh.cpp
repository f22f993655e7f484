#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "rocklab/geometry/frustum_mesh.h"
#include "rocklab/geometry/mesh_generate.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/triangle_mesh.h"
#include "rocklab/geometry/triangle_mesh_index.h"

using namespace rocklab::geometry;

TEST_CASE("mesh validation names the problem", "[geometry]") {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  mesh.triangles = {{0, 1, 2}};
  CHECK(mesh.validate() == "triangle 0 has zero area");
  mesh.triangles = {{0, 1, 5}};
  CHECK(mesh.validate().find("refers to vertex 5") != std::string::npos);
}

TEST_CASE("closest points through the AABB tree equal the brute force - and touches over a ball's candidates equal a search of the whole mesh", "[geometry]") {
  // The crusher's concave (a frustum seen from inside: every query point near
  // its concave side) and a 5120-triangle pebble, from points all around,
  // inside, on and far from the surface.
  FrustumSpec concave;
  concave.bottom_centre = Vec3(0, 0, 0.01);
  concave.top_centre = Vec3(0, 0, 0.06);
  concave.bottom_radius = 0.165;
  concave.top_radius = 0.128;
  concave.facing = FrustumFacing::TowardAxis;
  for (const TriangleMesh& mesh : {frustumMesh(concave), generateParticle(ParticleKind::Crushed, 7, 4)}) {
    const TriangleMeshIndex index(mesh);
    const AABB box = mesh.bounds();
    const Vec3 size = box.hi - box.lo;
    Rng rng(11);
    double worst = 0;
    std::size_t touches_seen = 0, more_than_one = 0;
    for (int k = 0; k < 3000; ++k) {
      const Vec3 u(rng.uniform(), rng.uniform(), rng.uniform());
      Vec3 p = box.lo - 0.2 * size + 1.4 * size.cwiseProduct(u);
      if (k % 10 == 0) p = mesh.vertices[k % mesh.vertices.size()];  // on a vertex
      const Vec3 brute = mesh.closestPoint(p);
      const Vec3 fast = index.closestPoint(p);
      worst = std::max(worst, (brute - fast).norm());
      // The distance can tie between triangles; the point then is the same.
      CHECK((fast - p).norm() == Approx((brute - p).norm()).margin(1e-13));
      // Within a radius: only nearby triangles, the brute force's point exactly.
      const double radius = 0.01 * (1 + k % 5);
      Vec3 near = Vec3::Zero();
      const bool within = index.closestPointWithin(p, radius, near);
      CHECK(within == ((brute - p).squaredNorm() < radius * radius));
      if (within) CHECK(near == brute);
      // A neighbour list's candidates (the triangles within radius + a skin, taken
      // where the point was before it moved by less than the skin) give that point
      // bit for bit, and miss nothing.
      const double skin = 0.004;
      const Vec3 before = p + 0.9 * skin * Vec3(u.x() - 0.5, u.z() - 0.5, u.y() - 0.5).normalized();
      std::vector<std::uint32_t> candidates;
      std::vector<double> distances;
      index.trianglesWithin(before, radius + skin, candidates, &distances);
      REQUIRE(distances.size() == candidates.size());
      CHECK(std::is_sorted(distances.begin(), distances.end()));  // nearest first
      Vec3 among = Vec3::Zero();
      CHECK(index.closestPointAmong(p, radius, candidates, among) == within);
      if (within) CHECK(among == near);
      // Told where the candidates were found and how far the point moved since, it
      // stops early and still finds that point bit for bit, in any order of the
      // candidates without the bounds.
      Vec3 bounded = Vec3::Zero();
      CHECK(index.closestPointAmong(p, radius, candidates, bounded, {distances, (p - before).norm()}) == within);
      if (within) CHECK(bounded == near);
      std::vector<std::uint32_t> reversed(candidates.rbegin(), candidates.rend());
      Vec3 any_order = Vec3::Zero();
      CHECK(index.closestPointAmong(p, radius, reversed, any_order) == within);
      if (within) CHECK(any_order == near);
      // The touches over the candidates, bounded or not, are touches() over the
      // whole mesh, and the nearest is closestPointAmong's point bit for bit.
      const auto all = index.touches(p, radius);
      std::vector<TriangleMeshIndex::Touch> listed, skipping;
      index.touchesAmong(p, radius, candidates, listed);
      index.touchesAmong(p, radius, candidates, skipping, {distances, (p - before).norm()});
      REQUIRE(listed.size() == all.size());
      REQUIRE(skipping.size() == all.size());
      CHECK(all.empty() != within);
      for (std::size_t t = 0; t < all.size(); ++t) {
        CHECK(listed[t].point == all[t].point);
        CHECK(skipping[t].point == all[t].point);
        CHECK(listed[t].triangle == all[t].triangle);
      }
      if (within) CHECK(listed[0].point == near);
      touches_seen += all.size();
      more_than_one += all.size() > 1 ? 1 : 0;
    }
    INFO("touches " << touches_seen << ", points with more than one " << more_than_one);
    CHECK(touches_seen > 100);
    INFO("triangles " << mesh.triangleCount());
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("a ball's touches on a mesh - one per contact and two in a concave crease", "[geometry]") {
  // A flat 3 x 3 grid (two triangles per square, a vertex where six meet): a ball
  // over a face, an edge, a diagonal or the centre vertex touches it once.
  TriangleMesh flat;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) flat.vertices.emplace_back(0.2 * i, 0.2 * j, 0.0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const std::uint32_t a = j * 3 + i, b = a + 1, c = a + 4, d = a + 3;
      flat.triangles.push_back({a, b, c});
      flat.triangles.push_back({a, c, d});
    }
  const TriangleMeshIndex grid(flat);
  for (const Vec3& p : {Vec3(0.05, -0.11, 0.009), Vec3(-0.1, -0.1, 0.009), Vec3(0, 0, 0.009), Vec3(0.001, 0, 0.009),
                        Vec3(0, 0.1, 0.009)}) {
    INFO("ball at " << p.transpose());
    const auto touches = grid.touches(p, 0.01);
    REQUIRE(touches.size() == 1);
    CHECK(touches[0].distance == Approx(0.009).margin(1e-15));
  }
  CHECK(grid.touches(Vec3(0.05, 0.05, 0.011), 0.01).empty());

  // A V-shaped groove (two faces at 90 degrees, concave seen from above, each
  // face two triangles): a ball resting in it touches both faces, each once,
  // with the normals of the faces; moved up one face, only that face.
  TriangleMesh groove;
  groove.vertices = {{-0.1, -0.2, 0.1}, {-0.1, 0.2, 0.1}, {0, -0.2, 0}, {0, 0.2, 0}, {0.1, -0.2, 0.1}, {0.1, 0.2, 0.1}};
  groove.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
  const TriangleMeshIndex v(groove);
  const double r = 0.01;
  const Vec3 rest(0, 0.03, r * std::sqrt(2.0) - 1e-4);  // overlapping each face by 1e-4 / sqrt(2)
  const auto both = v.touches(rest, r);
  REQUIRE(both.size() == 2);
  CHECK(std::abs((rest - both[0].point).normalized().dot((rest - both[1].point).normalized())) < 1e-9);  // 90 deg apart
  const Vec3 up_left(-0.03, 0.03, 0.03 + r * std::sqrt(2.0) - 1e-4);
  CHECK(v.touches(up_left, r).size() == 1);
  CHECK(v.touches(Vec3(0, 0.0, r - 1e-4), r).size() == 2);  // right above the crease line
  // The same faces as parts not welded together (each triangle its own vertices):
  // the touches are found by geometry, not by shared vertex indices, so a flat
  // floor near or over a seam still gives one touch and the groove two.
  auto unwelded = [](const TriangleMesh& m) {
    TriangleMesh u;
    for (const auto& f : m.triangles) {
      const auto base = static_cast<std::uint32_t>(u.vertices.size());
      for (int k = 0; k < 3; ++k) u.vertices.push_back(m.vertices[f[k]]);
      u.triangles.push_back({base, base + 1, base + 2});
    }
    return u;
  };
  const TriangleMeshIndex loose_grid(unwelded(flat));
  for (const Vec3& p : {Vec3(0.05, 0.002, 0.009), Vec3(0.05, 0.0, 0.009), Vec3(0.0, 0.0, 0.009), Vec3(0.1, 0.1, 0.009),
                        Vec3(-0.1, -0.1, 0.009)}) {
    INFO("ball at " << p.transpose() << " over the unwelded grid");
    CHECK(loose_grid.touches(p, 0.01).size() == 1);
  }
  CHECK(TriangleMeshIndex(unwelded(groove)).touches(rest, r).size() == 2);
  CHECK(TriangleMeshIndex(unwelded(groove)).touches(up_left, r).size() == 1);
  // A convex ridge (the groove upside down) and a cone's apex: one touch each.
  TriangleMesh ridge = groove;
  for (Vec3& p : ridge.vertices) p.z() = -p.z();
  CHECK(TriangleMeshIndex(ridge).touches(Vec3(0, 0.03, 0.009), r).size() == 1);
  FrustumSpec cone;
  cone.bottom_centre = Vec3::Zero();
  cone.top_centre = Vec3(0, 0, 0.05);
  cone.bottom_radius = 0.1;
  cone.top_radius = 0.0;
  const auto apex = TriangleMeshIndex(frustumMesh(cone)).touches(Vec3(0, 0, 0.059), r);
  REQUIRE(apex.size() == 1);
  CHECK(apex[0].distance == Approx(0.009).margin(1e-12));
}

TEST_CASE(
    "a pressed ball's contact energy is continuous across a concave crease: one smooth surface "
    "within the smooth angle, a corner beyond it",
    "[geometry]") {
  // Two faces meeting at 176.25 degrees along the y axis (a valley, the crease of
  // a 96-facet concave), and a ball of 4.15 mm pressed 0.2 mm into it, moved
  // across the crease in steps of 0.5 um. The Hertz energy of its touches (sum of
  // overlap^2.5) changes by about 2.5 x 16 nm / 0.2 mm a step when it is a
  // continuous function of the place. Counted as two faces, the second touch
  // switches on and off with almost the first one's overlap: the energy jumps by
  // about as much as it is.
  const double L = 0.02, W = 0.02, r = 4.15e-3;
  auto valleyOf = [&](double crease_deg) {
    const double rise = L * std::tan(0.5 * crease_deg * M_PI / 180.0);
    TriangleMesh valley;
    valley.vertices = {{-L, -W, rise}, {-L, W, rise}, {0, -W, 0},
                       {0, W, 0},      {L, -W, rise}, {L, W, rise}};
    valley.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
    return valley;
  };
  const TriangleMesh valley = valleyOf(3.75);
  double pressed = 0.2e-3;
  auto worstJump = [&](const TriangleMeshIndex& index, std::size_t& most_touches) {
    double worst = 0, previous = -1, largest = 0;
    most_touches = 0;
    for (int k = -6000; k <= 6000; ++k) {
      const Vec3 centre(0.5e-6 * k, 0.003, r - pressed);
      double energy = 0;
      const auto touches = index.touches(centre, r);
      most_touches = std::max(most_touches, touches.size());
      for (const auto& t : touches) energy += std::pow(r - t.distance, 2.5);
      if (previous >= 0) worst = std::max(worst, std::abs(energy - previous));
      previous = energy;
      largest = std::max(largest, energy);
    }
    return worst / largest;
  };
  std::size_t touches_smooth = 0, touches_faces = 0;
  const double smooth = worstJump(TriangleMeshIndex(valley, 10.0 * M_PI / 180.0), touches_smooth);
  const double faces = worstJump(TriangleMeshIndex(valley), touches_faces);
  INFO("largest energy step, smooth surface " << smooth << ", two faces " << faces);
  CHECK(touches_smooth == 1);
  CHECK(smooth < 1e-3);
  CHECK(touches_faces == 2);
  CHECK(faces > 0.3);  // the hazard the smooth angle removes
  // A crease sharper than the smooth angle is a corner, each face its own contact,
  // the far one's from its edge on: continuous too. A 20 degree crease and a ball
  // pressed 0.1 r into it, deeper than r (1 - cos 20 deg) = 0.06 r, where the far
  // face's touch appeared at once 0.042 r deep when the near face shadowed its edge.
  pressed = 0.1 * r;
  const TriangleMesh corner = valleyOf(20.0);
  const double corner_smooth =
      worstJump(TriangleMeshIndex(corner, 10.0 * M_PI / 180.0), touches_smooth);
  const double corner_shadowed = worstJump(TriangleMeshIndex(corner), touches_faces);
  INFO("20 degree crease: largest energy step, far edge a contact "
       << corner_smooth << ", shadowed " << corner_shadowed);
  CHECK(touches_smooth == 2);
  CHECK(corner_smooth < 1e-3);
  CHECK(corner_shadowed > 0.02);
  // The 90 degree groove: both faces, as before.
  const double rest_z = r * std::sqrt(2.0) - 1e-4;
  TriangleMesh groove;
  groove.vertices = {{-0.1, -0.2, 0.1}, {-0.1, 0.2, 0.1}, {0, -0.2, 0},
                     {0, 0.2, 0},       {0.1, -0.2, 0.1}, {0.1, 0.2, 0.1}};
  groove.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
  CHECK(TriangleMeshIndex(groove, 10.0 * M_PI / 180.0).touches(Vec3(0, 0.03, rest_z), r).size() ==
        2);
}
