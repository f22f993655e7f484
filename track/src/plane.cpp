#include "rocklab/track/plane.h"

#include <cmath>
#include <stdexcept>

namespace rocklab::track {

std::optional<geometry::Vec3> pixelToPlane(const geometry::Camera& camera, cv::Point2d pixel,
                                           const geometry::Vec3& plane_point, const geometry::Vec3& plane_normal) {
  geometry::Vec3 ray;
  try {
    ray = camera.pixelRay(geometry::Vec2(pixel.x, pixel.y));  // unit, world frame
  } catch (const std::domain_error&) {
    return std::nullopt;  // the lens folds over there
  }
  // Ray x = c + s d meets the plane (x − p) · n = 0 at s = (p − c) · n / (d · n).
  const geometry::Vec3 centre = camera.position();
  const double along = ray.dot(plane_normal);
  if (std::abs(along) <= 1e-12 * plane_normal.norm()) return std::nullopt;
  const double s = (plane_point - centre).dot(plane_normal) / along;
  if (!(s > 0.0)) return std::nullopt;
  return centre + s * ray;
}

std::optional<geometry::Vec3> pointToWorld(const geometry::Camera& camera, const TrackPoint& point,
                                           const geometry::Vec3& plane_point, const geometry::Vec3& plane_normal) {
  if (point.centre.allFinite()) return point.centre;
  return pixelToPlane(camera, point.pixel, plane_point, plane_normal);
}

}  // namespace rocklab::track
