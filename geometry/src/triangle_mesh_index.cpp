#include "rocklab/geometry/triangle_mesh_index.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <boost/iterator/function_output_iterator.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "rocklab/geometry/closest_point.h"

namespace rocklab::geometry {

namespace {
using Kernel = CGAL::Simple_cartesian<double>;
using Triangle = Kernel::Triangle_3;
using Point = Kernel::Point_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Point point(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

struct TriangleMeshIndex::Tree {
  TriangleMesh mesh;                 // the triangles' own coordinates (the exact point is computed on them)
  std::vector<Triangle> triangles;   // CGAL's copy, in mesh order (the tree refers to it)
  CgalTree tree;
  std::vector<std::vector<std::size_t>> vertex_triangles;                          // triangles around a vertex
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::size_t>> edge_triangles;  // (lo, hi) -> triangles

  Vec3 closestOn(std::size_t t, const Vec3& p) const {
    const auto& f = mesh.triangles[t];
    return closestPointOnTriangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]);
  }
};

namespace {

std::pair<std::uint32_t, std::uint32_t> edgeKey(std::uint32_t a, std::uint32_t b) { return {std::min(a, b), std::max(a, b)}; }

/// The vertices of triangle f on which q lies: 1 (a vertex), 2 (an edge) or 0 (inside the face).
std::vector<std::uint32_t> featureOf(const TriangleMesh& mesh, const std::array<std::uint32_t, 3>& f, const Vec3& q) {
  const Vec3 a = mesh.vertices[f[0]], b = mesh.vertices[f[1]], c = mesh.vertices[f[2]];
  const Vec3 n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  // Barycentric weights of q (on the triangle's plane): w_k = 0 on the edge opposite vertex k.
  const double w[3] = {(c - b).cross(q - b).dot(n) / area2, (a - c).cross(q - c).dot(n) / area2,
                       (b - a).cross(q - a).dot(n) / area2};
  constexpr double kOnEdge = 1e-9;
  std::vector<std::uint32_t> on;
  for (int k = 0; k < 3; ++k)
    if (w[k] > kOnEdge) on.push_back(f[k]);
  return on.size() == 3 ? std::vector<std::uint32_t>{} : on;
}

}  // namespace

TriangleMeshIndex::TriangleMeshIndex(const TriangleMesh& mesh) {
  auto t = std::make_shared<Tree>();
  t->mesh = mesh;
  t->triangles.reserve(mesh.triangles.size());
  for (const auto& f : mesh.triangles)
    t->triangles.emplace_back(point(mesh.vertices[f[0]]), point(mesh.vertices[f[1]]), point(mesh.vertices[f[2]]));
  t->vertex_triangles.resize(mesh.vertices.size());
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    const auto& f = mesh.triangles[k];
    for (int e = 0; e < 3; ++e) {
      t->vertex_triangles[f[e]].push_back(k);
      t->edge_triangles[edgeKey(f[e], f[(e + 1) % 3])].push_back(k);
    }
  }
  t->tree.insert(t->triangles.begin(), t->triangles.end());
  t->tree.build();
  t->tree.accelerate_distance_queries();
  // One query now: any search structure CGAL builds lazily is built here, on one
  // thread, not by the first of several threads that query at once.
  if (!t->triangles.empty()) (void)t->tree.closest_point_and_primitive(point(mesh.vertices[0]));
  tree_ = std::move(t);
}

std::size_t TriangleMeshIndex::closestTriangle(const Vec3& p) const {
  const auto hit = tree_->tree.closest_point_and_primitive(point(p));
  return static_cast<std::size_t>(hit.second - tree_->triangles.begin());
}

Vec3 TriangleMeshIndex::closestPoint(const Vec3& p) const {
  const auto& f = tree_->mesh.triangles[closestTriangle(p)];
  const auto& v = tree_->mesh.vertices;
  return closestPointOnTriangle(p, v[f[0]], v[f[1]], v[f[2]]);
}

namespace {

/// Calls visit(triangle index) for every triangle whose box meets p's box of half-size r.
template <class Visit>
void forTrianglesNear(const CgalTree& tree, const std::vector<Triangle>& triangles, const Vec3& p, double r,
                      Visit&& visit) {
  const CGAL::Bbox_3 box(p.x() - r, p.y() - r, p.z() - r, p.x() + r, p.y() + r, p.z() + r);
  tree.all_intersected_primitives(box, boost::make_function_output_iterator([&](const Primitive::Id& id) {
                                    visit(static_cast<std::size_t>(id - triangles.begin()));
                                  }));
}

}  // namespace

bool TriangleMeshIndex::closestPointWithin(const Vec3& p, double radius, Vec3& closest) const {
  const Tree& t = *tree_;
  double best = radius * radius;
  std::size_t best_triangle = 0;
  bool found = false;
  forTrianglesNear(t.tree, t.triangles, p, radius, [&](std::size_t k) {
    const Vec3 q = t.closestOn(k, p);
    const double d2 = (q - p).squaredNorm();
    if (d2 < best || (found && d2 == best && k < best_triangle)) {
      best = d2;
      best_triangle = k;
      closest = q;
      found = true;
    }
  });
  return found;
}

void TriangleMeshIndex::trianglesWithin(const Vec3& p, double radius, std::vector<std::uint32_t>& out,
                                        std::vector<double>* distances) const {
  const Tree& t = *tree_;
  const double r2 = radius * radius;
  std::vector<std::pair<double, std::uint32_t>> found;  // (distance^2, triangle)
  forTrianglesNear(t.tree, t.triangles, p, radius, [&](std::size_t k) {
    const double d2 = (t.closestOn(k, p) - p).squaredNorm();
    if (d2 < r2) found.emplace_back(d2, static_cast<std::uint32_t>(k));
  });
  std::sort(found.begin(), found.end());
  for (const auto& [d2, k] : found) {
    out.push_back(k);
    if (distances) distances->push_back(std::sqrt(d2));
  }
}

bool TriangleMeshIndex::closestPointAmong(const Vec3& p, double radius, std::span<const std::uint32_t> triangles,
                                          Vec3& closest, const CandidateDistances& bounds) const {
  const Tree& t = *tree_;
  double best = radius * radius;
  std::uint32_t best_triangle = 0;
  bool found = false;
  const bool bounded = bounds.then.size() == triangles.size();
  for (std::size_t c = 0; c < triangles.size(); ++c) {
    if (bounded) {
      // Nearest first: once a triangle's lower bound is above the best (with a
      // margin for round-off: metres, distances of mm), so are the rest's; an
      // equal one is still tested for the tie rule.
      const double lower = bounds.then[c] * (1 - 1e-9) - bounds.moved - 1e-12;
      if (lower > 0 && lower * lower > best) break;
    }
    const std::uint32_t k = triangles[c];
    const Vec3 q = t.closestOn(k, p);
    const double d2 = (q - p).squaredNorm();
    // The nearest, the lowest index of a tie: closestPointWithin's rule.
    if (d2 < best || (found && d2 == best && k < best_triangle)) {
      best = d2;
      best_triangle = k;
      closest = q;
      found = true;
    }
  }
  return found;
}

std::vector<TriangleMeshIndex::Touch> TriangleMeshIndex::touches(const Vec3& p, double r) const {
  const Tree& t = *tree_;
  std::vector<std::size_t> near;
  forTrianglesNear(t.tree, t.triangles, p, r, [&](std::size_t k) { near.push_back(k); });
  std::sort(near.begin(), near.end());

  std::vector<Touch> candidates;
  for (const std::size_t k : near) {
    const Vec3 q = t.closestOn(k, p);
    const double d = (q - p).norm();
    if (d < r) candidates.push_back({q, k, d});
  }
  // An edge or vertex touch is the same contact as a neighbour's when a triangle
  // sharing that feature comes closer (relative tolerance: ties are kept and merged).
  auto closerNeighbour = [&](const Touch& c, const std::vector<std::size_t>& around) {
    for (const std::size_t k : around)
      if (k != c.triangle && (t.closestOn(k, p) - p).norm() < c.distance * (1 - 1e-12) - 1e-300) return true;
    return false;
  };
  std::vector<Touch> kept;
  for (const Touch& c : candidates) {
    const std::vector<std::uint32_t> on = featureOf(t.mesh, t.mesh.triangles[c.triangle], c.point);
    if (on.size() == 1 && closerNeighbour(c, t.vertex_triangles[on[0]])) continue;
    if (on.size() == 2 && closerNeighbour(c, t.edge_triangles.at(edgeKey(on[0], on[1])))) continue;
    kept.push_back(c);
  }
  std::sort(kept.begin(), kept.end(), [](const Touch& a, const Touch& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.triangle < b.triangle;
  });
  // The same point reached from several triangles (a ridge, an apex): one touch.
  std::vector<Touch> merged;
  for (const Touch& c : kept) {
    const bool seen = std::any_of(merged.begin(), merged.end(), [&](const Touch& m) {
      return (m.point - c.point).norm() <= 1e-12 * std::max(1.0, c.distance + r);
    });
    if (!seen) merged.push_back(c);
  }
  return merged;
}

}  // namespace rocklab::geometry
