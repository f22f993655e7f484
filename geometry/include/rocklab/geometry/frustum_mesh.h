#pragma once
// The lateral surface of a conical frustum (or a cone, top radius 0) as a
// triangle mesh: the one generator behind every cone-crusher wall (mantle,
// concaves, mantle cap). The surface is open at its end discs (a wall, not a
// solid) and closed around: the seam's vertices are shared, so every edge but
// those of the end rings belongs to two triangles; a cone's apex is one vertex.
#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

/// Which way the triangles' normals (counter-clockwise winding) point.
enum class FrustumFacing {
  AwayFromAxis,  // outward: a mantle or cap, seen from the chamber outside it
  TowardAxis,    // inward: a concave, seen from the chamber inside it
};

struct FrustumSpec {
  Vec3 bottom_centre = Vec3::Zero();  // m, centre of the bottom disc
  Vec3 top_centre = Vec3::UnitZ();    // m, centre of the top disc (axis = top - bottom)
  double bottom_radius = 1.0;         // m, > 0
  double top_radius = 0.5;            // m, >= 0 (0: a cone with its apex at top_centre)
  // A unit direction perpendicular to the axis where the first generator lies (its
  // end vertices exactly on the line): the crusher puts it in the closed-side
  // section so that section is exact. Zero = any perpendicular direction.
  Vec3 first_generator = Vec3::Zero();
  int segments = 96;  // >= 3, triangles around (x 2 for a frustum)
  FrustumFacing facing = FrustumFacing::AwayFromAxis;
};

/// Throws std::invalid_argument naming the bad field (radii, segments, zero axis,
/// first_generator not perpendicular to the axis).
TriangleMesh frustumMesh(const FrustumSpec& spec);

}  // namespace rocklab::geometry
