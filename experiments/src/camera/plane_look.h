#pragma once
// How an infinite plane wall is drawn (WallLook: plane_size, plane_shape,
// plane_thickness): a square or a disc around the plane's point, flat or as a
// solid slab behind the plane. Built in the plane's own frame (z along the
// normal, the plane at z = 0); the frame builder places it in the wall's pose.
#include <vector>

#include "rocklab/experiments/scene.h"
#include "rocklab/geometry/triangle_mesh.h"
#include "rocklab/geometry/vec.h"

namespace rocklab::experiments {

/// Columns a, b, n: a right-handed frame whose third axis is the unit normal.
geometry::Mat3 planeFrame(const geometry::Vec3& normal);

/// The outline at z = 0 in the plane's frame, counter-clockwise about +z: 4
/// corners of the square of side plane_size, or 64 points on the disc of
/// diameter plane_size.
std::vector<geometry::Vec3> planeOutline(const WallLook& look);

/// The outline extruded to z = -plane_thickness (behind the plane, where no
/// ball is): a box or a 64-sided cylinder, closed at both ends.
geometry::TriangleMesh planeSlab(const WallLook& look);

}  // namespace rocklab::experiments
