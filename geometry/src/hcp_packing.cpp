#include "rocklab/geometry/hcp_packing.h"

#include <cmath>
#include <numbers>

#include "parameter_check.h"

namespace rocklab::geometry {

std::vector<Sphere> hcpPacking(double radius, double diameter, double angle_deg) {
  detail::requireParameter(radius > 0 && std::isfinite(radius), "hcpPacking", "radius", radius,
                           "must be > 0 (m)");
  detail::requireParameter(
      diameter >= 2 * radius && std::isfinite(diameter), "hcpPacking", "diameter", diameter,
      "must be >= twice the sphere radius (" + detail::formatValue(2 * radius) + " m)");
  detail::requireParameter(angle_deg >= 0 && angle_deg <= 90, "hcpPacking", "angle", angle_deg,
                           "must be in [0, 90] degrees");
  const double bound = 0.5 * diameter;
  const double sqrt3 = std::sqrt(3.0);
  const double layer = 2.0 * radius * std::sqrt(2.0 / 3.0);  // A to B spacing along y
  // In-plane triangular lattice: a1 = (2r, 0), a2 = (r, √3 r) in (x, z); B layers sit
  // over the centroids of A's triangles, offset (r, r/√3).
  const int layers = static_cast<int>(std::ceil(bound / layer)) + 1;
  const int rows = static_cast<int>(std::ceil(bound / (sqrt3 * radius))) + 1;
  const int cols = static_cast<int>(std::ceil(bound / (2 * radius))) + 1;
  const double angle = angle_deg * std::numbers::pi / 180.0;
  const Mat3 turn = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  std::vector<Sphere> spheres;
  for (int j = -layers; j <= layers; ++j) {
    const bool b_layer = (j % 2) != 0;
    const double off_x = b_layer ? radius : 0.0, off_z = b_layer ? radius / sqrt3 : 0.0;
    for (int k = -rows; k <= rows; ++k)
      for (int i = -cols - rows; i <= cols + rows; ++i) {
        const Vec3 p(2 * radius * i + radius * k + off_x, layer * j, sqrt3 * radius * k + off_z);
        // Relative slack so spheres touching the boundary by construction are kept.
        if (p.norm() + radius <= bound * (1 + 1e-12)) spheres.push_back({turn * p, radius});
      }
  }
  return spheres;
}

}  // namespace rocklab::geometry
