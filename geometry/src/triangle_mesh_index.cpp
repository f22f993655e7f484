#include "rocklab/geometry/triangle_mesh_index.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <boost/iterator/function_output_iterator.hpp>

#include <algorithm>
#include <array>
#include <cmath>
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

  Vec3 closestOn(std::size_t t, const Vec3& p) const {
    const auto& f = mesh.triangles[t];
    return closestPointOnTriangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]);
  }
};

namespace {

/// Whether q (a point of triangle f) lies on one of its edges or vertices rather
/// than inside the face.
bool onEdgeOrVertex(const TriangleMesh& mesh, const std::array<std::uint32_t, 3>& f, const Vec3& q) {
  const Vec3 a = mesh.vertices[f[0]], b = mesh.vertices[f[1]], c = mesh.vertices[f[2]];
  const Vec3 n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  // Barycentric weights of q (on the triangle's plane): w_k = 0 on the edge opposite vertex k.
  const double w[3] = {(c - b).cross(q - b).dot(n) / area2, (a - c).cross(q - c).dot(n) / area2,
                       (b - a).cross(q - a).dot(n) / area2};
  constexpr double kOnEdge = 1e-9;
  return !(w[0] > kOnEdge && w[1] > kOnEdge && w[2] > kOnEdge);
}

}  // namespace

TriangleMeshIndex::TriangleMeshIndex(const TriangleMesh& mesh, double smooth_angle)
    : smooth_cos_(smooth_angle > 0 ? std::cos(smooth_angle) : 2.0) {
  auto t = std::make_shared<Tree>();
  t->mesh = mesh;
  t->triangles.reserve(mesh.triangles.size());
  for (const auto& f : mesh.triangles)
    t->triangles.emplace_back(point(mesh.vertices[f[0]]), point(mesh.vertices[f[1]]), point(mesh.vertices[f[2]]));
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

namespace {

/// The touches among `candidates` (every triangle nearer to p than r, each with
/// its closest point and distance, in any order), once each: the rule of
/// TriangleMeshIndex::touches. An edge or vertex touch is the same contact as a
/// neighbour's when a nearer triangle holds that point (it shares the edge or
/// vertex); such a triangle is nearer than r too, so it is among the candidates.
/// A touch whose normal is within the smooth angle of a nearer kept one's
/// (cosine above `smooth_cos`) is that one's smooth surface seen again. With a
/// smooth angle, a nearer triangle across a concave crease sharper than it does
/// not shadow: that is a corner, and the far face's edge is a contact of its own.
void keepTouches(const TriangleMesh& mesh, std::vector<TriangleMeshIndex::Touch>& candidates,
                 const Vec3& p, double r, double smooth_cos,
                 std::vector<TriangleMeshIndex::Touch>& out) {
  using Touch = TriangleMeshIndex::Touch;
  out.clear();
  auto byDistance = [](const Touch& a, const Touch& b) {
    return a.distance2 != b.distance2 ? a.distance2 < b.distance2 : a.triangle < b.triangle;
  };
  if (candidates.size() == 1) {  // the common case: one triangle in reach
    out.push_back(candidates[0]);
    return;
  }
  std::sort(candidates.begin(), candidates.end(), byDistance);
  // Whether q lies on a triangle: by geometry, not by shared vertex indices, so
  // that an edge between parts not welded together counts as shared too.
  auto holds = [&](std::size_t triangle, const Vec3& q) {
    const auto& f = mesh.triangles[triangle];
    const Vec3 on = closestPointOnTriangle(q, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]);
    return (on - q).norm() <= 1e-9 * r;
  };
  // Whether `near` and `far` meet at q in a concave crease sharper than the smooth
  // angle: `far` rises towards p out of `near`'s plane, and their faces (both
  // normals turned towards p) differ by more than the smooth angle. Over such a
  // corner the far face's touch, at its edge, is r - |p - q| deep and goes on
  // continuously into its face touch inside the crease's wedge, so it counts; a
  // flatter crease is one smooth surface (below), and a convex one is shadowed.
  auto sharpConcave = [&](std::size_t near, std::size_t far, const Vec3& q) {
    if (smooth_cos > 1.0) return false;  // no smooth angle: every nearer face shadows
    auto towardsP = [&](std::size_t k) {
      const auto& f = mesh.triangles[k];
      const Vec3 n = (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                         .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]])
                         .normalized();
      return n.dot(p - q) < 0 ? Vec3(-n) : n;
    };
    const Vec3 n_near = towardsP(near), n_far = towardsP(far);
    const auto& g = mesh.triangles[far];
    const Vec3 centroid = (mesh.vertices[g[0]] + mesh.vertices[g[1]] + mesh.vertices[g[2]]) / 3.0;
    return n_near.dot(n_far) < smooth_cos && n_near.dot(centroid - q) > 0;
  };
  for (const Touch& c : candidates) {
    bool shadowed = false;
    if (onEdgeOrVertex(mesh, mesh.triangles[c.triangle], c.point)) {
      // Relative tolerance: ties are kept here and merged below.
      for (const Touch& o : candidates) {
        if (o.distance >= c.distance * (1 - 1e-12) - 1e-300) break;  // sorted: no nearer one follows
        if (o.triangle == c.triangle) continue;
        if (holds(o.triangle, c.point)) {
          if (sharpConcave(o.triangle, c.triangle, c.point)) continue;
          shadowed = true;
          break;
        }
      }
    }
    if (shadowed) continue;
    // The same point reached from several triangles (a ridge, an apex): one touch.
    const bool seen = std::any_of(out.begin(), out.end(), [&](const Touch& m) {
      return (m.point - c.point).norm() <= 1e-12 * std::max(1.0, c.distance + r);
    });
    if (seen) continue;
    // Normals as the contact takes them, from the surface towards the centre.
    const bool smooth = smooth_cos <= 1.0 && c.distance > 0 &&
                        std::any_of(out.begin(), out.end(), [&](const Touch& m) {
                          return m.distance > 0 && (p - m.point).dot(p - c.point) >
                                                       smooth_cos * m.distance * c.distance;
                        });
    if (!smooth) out.push_back(c);
  }
}

}  // namespace

std::vector<TriangleMeshIndex::Touch> TriangleMeshIndex::touches(const Vec3& p, double r) const {
  const Tree& t = *tree_;
  std::vector<Touch> candidates;
  forTrianglesNear(t.tree, t.triangles, p, r, [&](std::size_t k) {
    const Vec3 q = t.closestOn(k, p);
    const double d2 = (q - p).squaredNorm();
    if (d2 < r * r) candidates.push_back({q, k, std::sqrt(d2), d2});
  });
  std::vector<Touch> kept;
  keepTouches(t.mesh, candidates, p, r, smooth_cos_, kept);
  return kept;
}

void TriangleMeshIndex::touchesAmong(const Vec3& p, double r, std::span<const std::uint32_t> triangles,
                                     std::vector<Touch>& out, const CandidateDistances& bounds) const {
  const Tree& t = *tree_;
  thread_local std::vector<Touch> candidates;
  candidates.clear();
  const bool bounded = bounds.then.size() == triangles.size();
  const double r2 = r * r;
  for (std::size_t c = 0; c < triangles.size(); ++c) {
    if (bounded) {
      // Nearest first: once a triangle cannot come nearer than r, neither can the
      // rest (closestPointAmong's bound, with its margin for round-off).
      const double lower = bounds.then[c] * (1 - 1e-9) - bounds.moved - 1e-12;
      if (lower > 0 && lower * lower >= r2) break;
    }
    const std::uint32_t k = triangles[c];
    const Vec3 q = t.closestOn(k, p);
    const double d2 = (q - p).squaredNorm();
    if (d2 < r2) candidates.push_back({q, k, std::sqrt(d2), d2});
  }
  keepTouches(t.mesh, candidates, p, r, smooth_cos_, out);
}

}  // namespace rocklab::geometry
