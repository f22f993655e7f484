#include "rocklab/geometry/tangent_sphere.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "parameter_check.h"

namespace rocklab::geometry {

namespace {

// |det| of the Eq 5-10 matrix relative to the product of its row lengths: 1 for
// three orthogonal edges, 0 for coplanar centres. Below this the solve amplifies
// round-off by more than 1e9 and the group is treated as flat (no void).
constexpr double kFlatness = 1e-9;

// Barycentric slack: a centre this far outside a face (as a fraction of the
// tetrahedron) still counts as inside, for tangent spheres of symmetric groups
// whose centre lies on a face up to round-off.
constexpr double kInsideSlack = 1e-12;

// Positive roots of a r² + b r + c = 0, ascending; the linear equation when a ≈ 0
// (equal radii give v = 0 and a = −1; a vanishes only for special unequal groups).
std::vector<double> positiveRoots(double a, double b, double c) {
  std::vector<double> roots;
  const double scale = std::max({std::abs(a), std::abs(b), std::abs(c)});
  if (std::abs(a) <= 1e-14 * scale) {
    if (b != 0) roots.push_back(-c / b);
  } else {
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return {};
    // Numerically stable pair: q = -(b + sign(b) sqrt(disc)) / 2, roots q/a and c/q.
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    roots.push_back(q / a);
    if (q != 0) roots.push_back(c / q);
  }
  std::erase_if(roots, [](double r) { return !(r > 0) || !std::isfinite(r); });
  std::sort(roots.begin(), roots.end());
  return roots;
}

void checkGroup(const std::array<Sphere, 4>& group) {
  for (int k = 0; k < 4; ++k) {
    const Sphere& s = group[k];
    const std::string which = "sphere " + std::to_string(k + 1);
    detail::requireParameter(s.radius > 0 && std::isfinite(s.radius), "innerTangentSphere",
                             "radius of " + which, s.radius, "must be > 0 and finite");
    if (!s.centre.allFinite())
      throw std::invalid_argument("innerTangentSphere: centre of " + which + " is not finite");
  }
}

}  // namespace

const char* describe(TangentFailure failure) {
  switch (failure) {
    case TangentFailure::None:
      return "tangent sphere found";
    case TangentFailure::Degenerate:
      return "the four centres are (nearly) coplanar (Eq 5-10 singular)";
    case TangentFailure::NoPositiveRoot:
      return "the quadratic in r has no positive root";
    case TangentFailure::CentreOutside:
      return "the tangent sphere's centre lies outside the tetrahedron";
  }
  return "unknown";
}

TangentSolution innerTangentSphere(const std::array<Sphere, 4>& group) {
  checkGroup(group);
  const Vec3 origin = group[0].centre;
  const double r1 = group[0].radius;
  // Eq 5-10 with centre 1 at the origin: rows 2 (c_k − c_1), right-hand side
  // b0 + r b1 with b0_k = |c_k − c_1|² − r_k² + r_1² and b1_k = 2 (r_1 − r_k).
  Mat3 a;
  Vec3 b0, b1;
  for (int k = 1; k < 4; ++k) {
    const Vec3 d = group[k].centre - origin;
    const double rk = group[k].radius;
    a.row(k - 1) = 2.0 * d.transpose();
    b0[k - 1] = d.squaredNorm() - rk * rk + r1 * r1;
    b1[k - 1] = 2.0 * (r1 - rk);
  }
  const double row_product = a.row(0).norm() * a.row(1).norm() * a.row(2).norm();
  if (!(std::abs(a.determinant()) > kFlatness * row_product))
    return {std::nullopt, TangentFailure::Degenerate};
  const Eigen::PartialPivLU<Mat3> lu(a);
  const Vec3 u = lu.solve(b0), v = lu.solve(b1);  // centre − c_1 = u + r v
  // Eq 5-6: |u + r v|² = (r + r_1)²  →  (v·v − 1) r² + 2 (u·v − r_1) r + (u·u − r_1²) = 0.
  const std::vector<double> roots =
      positiveRoots(v.squaredNorm() - 1.0, 2.0 * (u.dot(v) - r1), u.squaredNorm() - r1 * r1);
  if (roots.empty()) return {std::nullopt, TangentFailure::NoPositiveRoot};
  // Inside the tetrahedron: barycentric coordinates from the edge matrix (λ1 = 1 − Σ λ).
  Mat3 edges;
  for (int k = 1; k < 4; ++k) edges.col(k - 1) = group[k].centre - origin;
  const Eigen::PartialPivLU<Mat3> edge_lu(edges);
  for (double r : roots) {
    const Vec3 rel = u + r * v;
    const Vec3 lambda = edge_lu.solve(rel);
    const double lambda0 = 1.0 - lambda.sum();
    if (lambda.minCoeff() >= -kInsideSlack && lambda0 >= -kInsideSlack)
      return {Sphere{origin + rel, r}, TangentFailure::None};
  }
  return {std::nullopt, TangentFailure::CentreOutside};
}

}  // namespace rocklab::geometry
