#include "camera/plane_look.h"

#include <cmath>
#include <cstdint>
#include <numbers>

namespace rocklab::experiments {

using geometry::Vec3;

namespace {
constexpr int kDiscSides = 64;  // the chord error is 0.12 % of the radius
}

geometry::Mat3 planeFrame(const Vec3& normal) {
  const Vec3 n = normal.normalized();
  const Vec3 a = n.unitOrthogonal(), b = n.cross(a);
  geometry::Mat3 frame;
  frame << a, b, n;
  return frame;
}

std::vector<Vec3> planeOutline(const WallLook& look) {
  const double h = 0.5 * look.plane_size;
  if (!look.plane_disc) return {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
  std::vector<Vec3> outline;
  for (int k = 0; k < kDiscSides; ++k) {
    const double phi = 2 * std::numbers::pi * k / kDiscSides;
    outline.emplace_back(h * std::cos(phi), h * std::sin(phi), 0.0);
  }
  return outline;
}

geometry::TriangleMesh planeSlab(const WallLook& look) {
  const std::vector<Vec3> outline = planeOutline(look);
  const auto m = static_cast<std::uint32_t>(outline.size());
  geometry::TriangleMesh mesh;
  for (const Vec3& v : outline) mesh.vertices.push_back(v);  // front ring
  for (const Vec3& v : outline)
    mesh.vertices.push_back(v - Vec3(0, 0, look.plane_thickness));  // back ring
  mesh.vertices.push_back(Vec3::Zero());                            // front centre 2m
  mesh.vertices.push_back(Vec3(0, 0, -look.plane_thickness));       // back centre 2m + 1
  for (std::uint32_t k = 0; k < m; ++k) {
    const std::uint32_t next = (k + 1) % m;
    mesh.triangles.push_back({2 * m, k, next});              // front face, normal +z
    mesh.triangles.push_back({2 * m + 1, m + next, m + k});  // back face, normal -z
    mesh.triangles.push_back({k, m + k, m + next});          // side, outward
    mesh.triangles.push_back({k, m + next, next});
  }
  return mesh;
}

}  // namespace rocklab::experiments
