#pragma once
// Per-frame values shared by every draw: the camera → clip mapping of the canvas,
// lighting and gain, in the layout the shaders take them.
#include <array>

#include <Eigen/Core>

#include "rocklab/geometry/vec.h"
#include "lens.h"

namespace rocklab::render::detail {

struct ViewUniforms {
  Eigen::Matrix4f clipFromCamera;        // column-major, as glUniformMatrix4fv wants
  std::array<float, 4> intrinsics{};     // fx, fy, cx, cy of the canvas
  std::array<float, 2> depthMap{};       // z_ndc = depthMap[0] + depthMap[1] / z
  std::array<float, 4> lighting{};       // ambient, diffuse, specular, shininess
  float gain = 1.0f;
  // The cut-away's planes in the camera frame, (n, d) with n unit: a wall fragment at
  // x with n · x + d > 0 for both is discarded. (0, 0, 0, -1) first: no cut;
  // (0, 0, 0, 1) second: the first plane alone (CutPlane::removes).
  std::array<float, 4> cutPlane{0.0f, 0.0f, 0.0f, -1.0f};
  std::array<float, 4> cutWedge{0.0f, 0.0f, 0.0f, 1.0f};
};

/// Camera → GL for a canvas (derivation in renderer.cpp): OpenCV pixel (u, v)
/// lands at gl_FragCoord (u + 0.5, v + 0.5), depth [near, far] → [-1, 1].
ViewUniforms makeViewUniforms(const Canvas& canvas, double nearClip, double farClip);

/// x_cam = rotation x + translation, as a 4×4 float matrix (column-major).
Eigen::Matrix4f rigidMatrix(const geometry::Mat3& rotation, const geometry::Vec3& translation);

}  // namespace rocklab::render::detail
