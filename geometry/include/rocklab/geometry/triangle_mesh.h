#pragma once
// An indexed triangle mesh (vertices in metres) with the queries walls need.
#include <array>
#include <limits>
#include <cstdint>
#include <string>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::geometry {

struct AABB {
  Vec3 lo{Vec3::Constant(std::numeric_limits<double>::infinity())};
  Vec3 hi{Vec3::Constant(-std::numeric_limits<double>::infinity())};
  void extend(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  /// Distance from p to the box (0 inside).
  double distance(const Vec3& p) const {
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
  }
};

struct TriangleMesh {
  std::vector<Vec3> vertices;                      // [nv] m
  std::vector<std::array<std::uint32_t, 3>> triangles;  // [nt] vertex indices, counter-clockwise

  std::size_t triangleCount() const { return triangles.size(); }
  AABB bounds() const;
  /// Closest point on the whole mesh surface (brute force over triangles).
  Vec3 closestPoint(const Vec3& p) const;
  /// Checks coordinates (finite), indices and degenerate triangles; returns an
  /// empty string or a message.
  std::string validate() const;
  /// "" or which vertex has a NaN or infinite coordinate (a NaN vertex would
  /// otherwise read as a zero-area triangle or a flat surface).
  std::string nonFiniteVertex() const;
};

}  // namespace rocklab::geometry
