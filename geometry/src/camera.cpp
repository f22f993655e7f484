#include "rocklab/geometry/camera.h"

#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rocklab::geometry {

namespace {

[[noreturn]] void invalid(const std::string& field, const std::string& what) {
  throw std::invalid_argument("camera." + field + " " + what);
}

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Radial distortion of a normalised radius: r_d = r (1 + k1 r² + k2 r⁴).
double distortRadius(double r, double k1, double k2) {
  const double r2 = r * r;
  return r * (1.0 + r2 * (k1 + r2 * k2));
}

// d r_d / d r = 1 + 3 k1 r² + 5 k2 r⁴, smallest value over [0, r]: a quadratic in
// s = r², so its minimum is at an end or at the vertex s* = -3 k1 / (10 k2).
double minSlope(double r, double k1, double k2) {
  auto slope = [&](double s) { return 1.0 + s * (3.0 * k1 + 5.0 * k2 * s); };
  const double s1 = r * r;
  double m = std::min(slope(0.0), slope(s1));
  if (k2 > 0.0) {
    const double vertex = -3.0 * k1 / (10.0 * k2);
    if (vertex > 0.0 && vertex < s1) m = std::min(m, slope(vertex));
  }
  return m;
}

}  // namespace

Camera Camera::withFieldOfView(int width, int height, double horizontalFovDeg) {
  if (!(horizontalFovDeg > 0.0 && horizontalFovDeg < 180.0))
    invalid("horizontalFovDeg", "must be in (0, 180) degrees (got " + str(horizontalFovDeg) + ")");
  Camera c;
  c.width = width;
  c.height = height;
  const double half = 0.5 * horizontalFovDeg * std::numbers::pi / 180.0;
  c.fx = c.fy = 0.5 * width / std::tan(half);
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  return c;
}

void Camera::validate() const {
  if (width <= 0) invalid("width", "must be > 0 pixels (got " + std::to_string(width) + ")");
  if (height <= 0) invalid("height", "must be > 0 pixels (got " + std::to_string(height) + ")");
  if (!(fx > 0.0) || !std::isfinite(fx)) invalid("fx", "must be a finite focal length > 0 pixels (got " + str(fx) + ")");
  if (!(fy > 0.0) || !std::isfinite(fy)) invalid("fy", "must be a finite focal length > 0 pixels (got " + str(fy) + ")");
  if (!std::isfinite(cx)) invalid("cx", "must be finite (got " + str(cx) + ")");
  if (!std::isfinite(cy)) invalid("cy", "must be finite (got " + str(cy) + ")");
  if (!std::isfinite(k1)) invalid("k1", "must be finite (got " + str(k1) + ")");
  if (!std::isfinite(k2)) invalid("k2", "must be finite (got " + str(k2) + ")");
  if (!rotation.allFinite()) invalid("rotation", "must be finite");
  const double orthoError = (rotation.transpose() * rotation - Mat3::Identity()).norm();
  if (orthoError > 1e-6)
    invalid("rotation", "must be orthonormal (|RᵀR − I| = " + str(orthoError) + ")");
  if (rotation.determinant() < 0.0) invalid("rotation", "must be a proper rotation (det = -1, a reflection)");
  if (!translation.allFinite()) invalid("translation", "must be finite");
  if (!(frameRate > 0.0) || !std::isfinite(frameRate))
    invalid("frameRate", "must be > 0 frames/s (got " + str(frameRate) + ")");
  if (!(exposureTime >= 0.0) || exposureTime > 1.0 / frameRate)
    invalid("exposureTime", "must be in [0, 1/frameRate] = [0, " + str(1.0 / frameRate) + "] s (got " +
                                str(exposureTime) + ")");
  // The distortion must be invertible over the whole image: the corners are the
  // farthest points from the principal point.
  if (hasDistortion()) {
    for (double u : {-0.5, width - 0.5})
      for (double v : {-0.5, height - 0.5}) {
        try {
          (void)undistort(Vec2((u - cx) / fx, (v - cy) / fy));
        } catch (const std::domain_error& e) {
          invalid("k1", "and camera.k2 fold the image over at the corner (" + str(u) + ", " + str(v) +
                            "): " + e.what());
        }
      }
  }
}

void Camera::lookAt(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 view = target - eye;
  if (!(view.norm() > 0.0)) throw std::invalid_argument("camera lookAt: eye and target coincide");
  const Vec3 forward = view.normalized();                 // camera +z
  const Vec3 side = forward.cross(up);                    // camera +x (right)
  if (!(side.norm() > 1e-12 * up.norm()) || !(up.norm() > 0.0))
    throw std::invalid_argument("camera lookAt: up is zero or parallel to the view direction");
  const Vec3 right = side.normalized();
  const Vec3 down = forward.cross(right);                 // camera +y (down)
  rotation.row(0) = right.transpose();
  rotation.row(1) = down.transpose();
  rotation.row(2) = forward.transpose();
  translation = -rotation * eye;
}

Vec2 Camera::distort(const Vec2& normalised) const {
  const double r2 = normalised.squaredNorm();
  return normalised * (1.0 + r2 * (k1 + r2 * k2));
}

Vec2 Camera::undistort(const Vec2& distorted) const {
  if (!hasDistortion()) return distorted;
  const double rd = distorted.norm();
  if (rd == 0.0) return distorted;
  // Newton on f(r) = r (1 + k1 r² + k2 r⁴) − r_d from r = r_d.
  double r = rd;
  for (int it = 0; it < 50; ++it) {
    const double r2 = r * r;
    const double slope = 1.0 + r2 * (3.0 * k1 + 5.0 * k2 * r2);
    if (!(slope > 0.0)) break;
    const double step = (distortRadius(r, k1, k2) - rd) / slope;
    r -= step;
    if (!(r > 0.0)) break;
    if (std::abs(step) <= 1e-15 * r) break;
  }
  if (!(r > 0.0) || !(std::abs(distortRadius(r, k1, k2) - rd) <= 1e-12 * (1.0 + rd)) || !(minSlope(r, k1, k2) > 0.0))
    throw std::domain_error("radial distortion is not invertible at distorted radius " + str(rd));
  return distorted * (r / rd);
}

Vec2 Camera::project(const Vec3& world) const {
  const Vec3 c = toCamera(world);
  const Vec2 d = distort(Vec2(c.x() / c.z(), c.y() / c.z()));
  return Vec2(fx * d.x() + cx, fy * d.y() + cy);
}

Vec3 Camera::pixelRay(const Vec2& pixel) const {
  const Vec2 n = undistort(Vec2((pixel.x() - cx) / fx, (pixel.y() - cy) / fy));
  return rotation.transpose() * Vec3(n.x(), n.y(), 1.0).normalized();
}

}  // namespace rocklab::geometry
