#pragma once
// Cameras, scenes and measurements shared by the render tests.
#include <memory>

#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/render/frame.h"
#include "support/cameras.h"

namespace rocklab::render::test {

using geometry::Camera;
using geometry::Vec2;
using rocklab::test::CameraPose;
using rocklab::test::kSceneView;
using rocklab::test::labCamera;

/// The lab camera's scene view at a small size: focal length 1.25 × width, principal
/// point at the image centre.
inline Camera smallSceneCamera(int width, int height) {
  Camera c = labCamera(kSceneView);
  c.width = width;
  c.height = height;
  c.fx = c.fy = 1.25 * width;
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  return c;
}

/// A box mesh [lo, hi] (12 triangles).
inline std::shared_ptr<const geometry::TriangleMesh> boxMesh(const Vec3& lo, const Vec3& hi) {
  auto m = std::make_shared<geometry::TriangleMesh>();
  for (int k = 0; k < 8; ++k) m->vertices.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  m->triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                  {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

/// The golden scene: floor and back wall, grey pebbles, two red markers (one
/// overlapping a pebble like a clump member), a box mesh, and a transparent
/// Perspex side wall between part of the scene and the camera.
inline FrameDescription tinyScene() {
  FrameDescription f;
  f.polygons.push_back({{{-0.3, -0.2, 0}, {0.3, -0.2, 0}, {0.3, 0.2, 0}, {-0.3, 0.2, 0}}, {0.40f, 0.38f, 0.35f}, 1.0f});
  f.polygons.push_back({{{-0.3, 0.2, 0}, {0.3, 0.2, 0}, {0.3, 0.2, 0.3}, {-0.3, 0.2, 0.3}}, {0.30f, 0.32f, 0.36f}, 1.0f});
  const double r = 0.014;
  f.spheres.push_back({Vec3(-0.06, 0.0, r), r, kGreyPebble, Vec3::Zero()});
  f.spheres.push_back({Vec3(-0.035, 0.01, r), r, kGreyPebble, Vec3::Zero()});
  f.spheres.push_back({Vec3(-0.045, 0.0, 2.6 * r), r, kRedMarker, Vec3::Zero()});
  f.spheres.push_back({Vec3(0.03, -0.04, 0.6 * r), 0.6 * r, kGreyPebble, Vec3::Zero()});
  f.spheres.push_back({Vec3(0.06, 0.05, r), r, kRedMarker, Vec3::Zero()});
  f.spheres.push_back({Vec3(0.0, 0.08, 1.5 * r), 1.5 * r, kGreyPebble, Vec3::Zero()});
  f.meshes.push_back({boxMesh(Vec3(0.09, -0.02, 0), Vec3(0.14, 0.03, 0.04)), Mat3::Identity(), Vec3::Zero(),
                      {0.55f, 0.45f, 0.30f}, 1.0f});
  // Perspex: a vertical plane y = −0.07, in front of the left half of the scene.
  f.polygons.push_back({{{-0.3, -0.07, 0}, {0.0, -0.07, 0}, {0.0, -0.07, 0.12}, {-0.3, -0.07, 0.12}}, kPerspex, 0.25f});
  return f;
}

}  // namespace rocklab::render::test
