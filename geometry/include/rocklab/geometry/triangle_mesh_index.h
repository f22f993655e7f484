#pragma once
// Closest points on a triangle mesh through a spatial index: CGAL's AABB tree
// over the mesh's triangles (with its search tree for distance queries), built
// once. A mesh wall asks this for every ball near it on every step; the brute
// force of TriangleMesh::closestPoint visits every triangle (the cone crusher's
// walls have 96-192 each, an imported wall thousands).
//
// The tree finds the nearest triangle; the point on it is computed by the same
// closestPointOnTriangle as the brute force, so both give the same point up to
// round-off (a tie between triangles sharing an edge or vertex is the same point).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

/// Where a ball's candidate triangles were found (TriangleMeshIndex::trianglesWithin):
/// the distance of each from the point then, nearest first, and how far the point
/// and the mesh have moved since, at most (m). No triangle can now be nearer than
/// its distance then less `moved`.
struct CandidateDistances {
  std::span<const double> then;
  double moved = 0;
};

class TriangleMeshIndex {
 public:
  TriangleMeshIndex() = default;  // no mesh: closestPoint must not be called
  /// Copies what it needs of `mesh` (which must pass validate()). Faces that meet
  /// at less than `smooth_angle` (rad) stand for one smooth surface (touches()).
  explicit TriangleMeshIndex(const TriangleMesh& mesh, double smooth_angle = 0.0);

  bool empty() const { return !tree_; }
  /// Closest point on the mesh surface to p.
  Vec3 closestPoint(const Vec3& p) const;
  /// Index (into mesh.triangles) of a triangle holding that point.
  std::size_t closestTriangle(const Vec3& p) const;
  /// The closest point on the mesh if it is nearer to p than `radius` (false
  /// otherwise): only the triangles whose boxes meet p's box are visited, and the
  /// point is the brute force's (the first triangle in mesh order on a tie), so a
  /// ball's contact costs a few triangles whatever the mesh.
  bool closestPointWithin(const Vec3& p, double radius, Vec3& closest) const;

  /// Appends to `out` every triangle nearer to p than `radius`, nearest first
  /// (ties by index), and to `distances` (when given) each one's distance from p:
  /// the candidates of a ball for as long as it and the mesh move less than the
  /// margin `radius` holds beyond the ball (a neighbour list's skin).
  void trianglesWithin(const Vec3& p, double radius, std::vector<std::uint32_t>& out,
                       std::vector<double>* distances = nullptr) const;
  /// closestPointWithin over the given triangles only: the same point (the
  /// nearest triangle, the lowest index on a tie, in whatever order they come),
  /// when they hold every triangle nearer to p than `radius`, at the cost of a few
  /// closest-point tests instead of a tree query. With `bounds` (the triangles in
  /// trianglesWithin's order) the search stops at the first triangle that cannot
  /// come as near as the best so far: the same point, fewer tests.
  bool closestPointAmong(const Vec3& p, double radius, std::span<const std::uint32_t> triangles, Vec3& closest,
                         const CandidateDistances& bounds = {}) const;

  /// A point where a ball centred at p touches the surface.
  struct Touch {
    Vec3 point;               // closest point on `triangle`
    std::size_t triangle = 0;
    double distance = 0;      // m, |p - point|
    double distance2 = 0;     // m^2, its square as computed (the order of touches)
  };
  /// Every place where a ball (centre p, radius r) touches the mesh, once each:
  /// the local minima of the distance from p over the surface closer than r. A
  /// point on a triangle's face is one; a point on an edge or a vertex is one only
  /// when no triangle sharing that edge or vertex comes closer (else it is the
  /// same contact seen from a neighbour: a flat mesh split into triangles, a
  /// convex ridge or a cone's apex give one touch), and touches at the same point
  /// are merged. A ball in a concave crease touching both faces gets two, unless
  /// their normals differ by less than the smooth angle: such a crease is the
  /// tessellation of a smooth surface (a cone's 96 facets), which a ball touches
  /// once, so only the nearer touch is kept. That keeps the contact energy a
  /// continuous function of the ball's place: two touches whose normals differ by
  /// theta appear only inside a wedge of angle theta over the crease, and where the
  /// farther one appears its overlap is already that of the nearer less about
  /// r (1 - cos theta) (a few micrometres at 3.75 degrees), so counting both would
  /// switch a second, almost equal contact on and off as a pressed ball crosses
  /// the crease (docs/crusher.md: the coarse bonded run's jam). A concave crease
  /// sharper than the smooth angle is a corner: the nearer face does not shadow
  /// the far face's edge there, whose touch goes on continuously into its face
  /// touch inside the wedge. Without a smooth angle (0) every nearer face shadows.
  /// Sorted by squared distance, then triangle (closestPointAmong's rule).
  std::vector<Touch> touches(const Vec3& p, double r) const;
  /// touches() over the given triangles only, into `out` (cleared first): the same
  /// touches when they hold every triangle nearer to p than r (a ball's candidates,
  /// trianglesWithin with r + skin). With `bounds` the triangles that cannot come
  /// nearer than r are not tested. The nearest touch is closestPointAmong's point.
  void touchesAmong(const Vec3& p, double r, std::span<const std::uint32_t> triangles, std::vector<Touch>& out,
                    const CandidateDistances& bounds = {}) const;

 private:
  struct Tree;
  std::shared_ptr<const Tree> tree_;  // shared: copies of an index (and of a wall) share one tree
  double smooth_cos_ = 2.0;           // cos of the smooth angle; 2: no two normals are that close
};

}  // namespace rocklab::geometry
