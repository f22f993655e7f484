#include "view.h"

namespace rocklab::render::detail {

// Camera → GL. The camera frame is OpenCV's (x right, y down, z forward) and the
// pixel u = fx X/Z + cx has its centre at window x = u + 0.5. With w_clip = Z:
//   x_ndc = 2 (u + 0.5) / W − 1   ⇒  x_clip = (2 fx / W) X + ((2 cx + 1) / W − 1) Z
//   y_ndc = 2 (v + 0.5) / H − 1   ⇒  y_clip = (2 fy / H) Y + ((2 cy + 1) / H − 1) Z
//   z_ndc = A + B / Z, −1 at near, +1 at far ⇒ A = (f + n)/(f − n), B = −2 f n/(f − n)
// y is *not* flipped: image row v is GL window row v, so glReadPixels (which
// returns window row 0 first) gives the image top row first and no flip is needed.
// The flip mirrors the winding of triangles; nothing is culled, so it does not matter.
ViewUniforms makeViewUniforms(const Canvas& canvas, double nearClip, double farClip) {
  const double w = canvas.width, h = canvas.height, n = nearClip, f = farClip;
  const double a = (f + n) / (f - n), b = -2.0 * f * n / (f - n);
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2.0 * canvas.fx / w;
  m(0, 2) = (2.0 * canvas.cx + 1.0) / w - 1.0;
  m(1, 1) = 2.0 * canvas.fy / h;
  m(1, 2) = (2.0 * canvas.cy + 1.0) / h - 1.0;
  m(2, 2) = a;
  m(2, 3) = b;
  m(3, 2) = 1.0;
  ViewUniforms u;
  u.clipFromCamera = m.cast<float>();
  u.intrinsics = {static_cast<float>(canvas.fx), static_cast<float>(canvas.fy), static_cast<float>(canvas.cx),
                  static_cast<float>(canvas.cy)};
  u.depthMap = {static_cast<float>(a), static_cast<float>(b)};
  return u;
}

Eigen::Matrix4f rigidMatrix(const geometry::Mat3& rotation, const geometry::Vec3& translation) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation;
  m.topRightCorner<3, 1>() = translation;
  return m.cast<float>();
}

}  // namespace rocklab::render::detail
