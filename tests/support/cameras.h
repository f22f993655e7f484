#pragma once
// The test camera shared by the render and track tests (and their benchmarks):
// the lab camera's intrinsics, posed where a suite needs it.
#include "rocklab/geometry/camera.h"

namespace rocklab::test {

inline constexpr double kLabFrameRate = 500.0;  // frames/s, the lab camera

/// Where a test camera stands and what it looks at (z up).
struct CameraPose {
  geometry::Vec3 eye;
  geometry::Vec3 target;
};

/// From (0.1, −0.6, 0.25) m at (0, 0, 0.05) m: a posed, non-trivial view of a
/// small scene at the origin (the render tests' golden scene).
inline const CameraPose kSceneView{geometry::Vec3(0.1, -0.6, 0.25), geometry::Vec3(0.0, 0.0, 0.05)};

/// Looking down at about 38° on the chute base (z = 0) from the camera side (−y),
/// as the lab camera sees the chute (the track tests).
inline const CameraPose kObliqueChuteView{geometry::Vec3(0.05, -0.45, 0.35),
                                          geometry::Vec3(0.0, 0.0, 0.0)};

/// 640×480, fx 800, fy 805, a little off-centre principal point, radial
/// distortion k1, k2, the lab camera's frame rate, posed at `pose`.
inline geometry::Camera labCamera(const CameraPose& pose, double k1 = 0.0, double k2 = 0.0) {
  geometry::Camera c;
  c.fx = 800.0;
  c.fy = 805.0;
  c.cx = 322.3;
  c.cy = 236.8;
  c.k1 = k1;
  c.k2 = k2;
  c.frameRate = kLabFrameRate;
  c.lookAt(pose.eye, pose.target, geometry::Vec3(0, 0, 1));
  return c;
}

}  // namespace rocklab::test
