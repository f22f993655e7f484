#include "rocklab/geometry/frustum_mesh.h"

#include <cmath>
#include <numbers>

#include "parameter_check.h"

namespace rocklab::geometry {

TriangleMesh frustumMesh(const FrustumSpec& spec) {
  using detail::requireParameter;
  const char* fn = "frustumMesh";
  const Vec3 axis = spec.top_centre - spec.bottom_centre;
  requireParameter(axis.norm() > 0, fn, "|top_centre - bottom_centre|", axis.norm(), "must be > 0 m");
  requireParameter(spec.bottom_radius > 0, fn, "bottom_radius", spec.bottom_radius, "must be > 0 m");
  requireParameter(spec.top_radius >= 0, fn, "top_radius", spec.top_radius, "must be >= 0 m (0: a cone)");
  requireParameter(spec.segments >= 3, fn, "segments", spec.segments, "must be >= 3");
  const Vec3 a = axis.normalized();
  Vec3 u = spec.first_generator;
  if (u.isZero(0)) u = a.unitOrthogonal();
  requireParameter(std::abs(u.normalized().dot(a)) < 1e-9, fn, "first_generator . axis",
                   u.normalized().dot(a), "must be 0 (perpendicular to the axis)");
  u.normalize();
  const Vec3 w = a.cross(u);  // u, w, a right-handed: angle grows counter-clockwise about a

  const auto n = static_cast<std::uint32_t>(spec.segments);
  const bool cone = spec.top_radius == 0;
  TriangleMesh m;
  for (std::uint32_t k = 0; k < n; ++k) {
    const double phi = 2 * std::numbers::pi * k / n;
    m.vertices.push_back(spec.bottom_centre + spec.bottom_radius * (std::cos(phi) * u + std::sin(phi) * w));
  }
  if (cone) {
    m.vertices.push_back(spec.top_centre);
  } else {
    for (std::uint32_t k = 0; k < n; ++k) {
      const double phi = 2 * std::numbers::pi * k / n;
      m.vertices.push_back(spec.top_centre + spec.top_radius * (std::cos(phi) * u + std::sin(phi) * w));
    }
  }
  // Bottom k, k+1 and top k: counter-clockwise seen from outside (normal away
  // from the axis) for a ring ordered counter-clockwise about the axis.
  const bool outward = spec.facing == FrustumFacing::AwayFromAxis;
  auto add = [&](std::uint32_t p, std::uint32_t q, std::uint32_t r) {
    if (outward) m.triangles.push_back({p, q, r});
    else m.triangles.push_back({p, r, q});
  };
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t b0 = k, b1 = (k + 1) % n;
    if (cone) {
      add(b0, b1, n);
    } else {
      add(b0, b1, n + b1);
      add(b0, n + b1, n + b0);
    }
  }
  return m;
}

}  // namespace rocklab::geometry
