#pragma once
// What the renderer draws: a *frame description*, built by the caller (experiments
// converts a simulation snapshot into one). Nothing here knows about the simulation.
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "rocklab/geometry/triangle_mesh.h"
#include "rocklab/geometry/vec.h"

namespace rocklab::render {

using geometry::Mat3;
using geometry::Vec3;

/// Colour, each channel in [0, 1] (sRGB values as written to the image, no gamma step).
struct Rgb {
  float r = 0.0f;
  float g = 0.0f;
  float b = 0.0f;
};

// Lab materials: grey pebbles, red marker pebbles, the dark backdrop.
inline constexpr Rgb kGreyPebble{0.56f, 0.55f, 0.52f};
inline constexpr Rgb kRedMarker{0.82f, 0.09f, 0.07f};
inline constexpr Rgb kBackdrop{0.12f, 0.13f, 0.15f};
inline constexpr Rgb kPerspex{0.80f, 0.90f, 0.95f};

/// A sphere (clump member or ball).
struct SphereInstance {
  Vec3 centre = Vec3::Zero();    // m, world
  double radius = 0.0;           // m
  Rgb colour = kGreyPebble;
  Vec3 velocity = Vec3::Zero();  // m/s, world; used only for motion blur
};

/// A flat convex polygon (a wall), vertices in order around it (either sense).
/// opacity < 1 makes it transparent (a Perspex side wall): drawn after all opaque
/// geometry, blended, without writing depth.
struct Polygon {
  std::vector<Vec3> vertices;  // m, world
  Rgb colour{0.45f, 0.45f, 0.47f};
  float opacity = 1.0f;        // [0, 1]
};

/// A triangle mesh (a mesh wall) placed by a rigid pose: x_world = rotation x_mesh + translation.
/// The renderer keeps the mesh's vertex buffer while the shared mesh object lives,
/// so a moving wall costs one matrix per frame; do not modify a mesh once drawn
/// (make a new one).
struct MeshInstance {
  std::shared_ptr<const geometry::TriangleMesh> mesh;
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();  // m
  Rgb colour{0.45f, 0.45f, 0.47f};
  float opacity = 1.0f;             // [0, 1]
};

/// A cut-away (a clip plane): what lies beyond the plane, n · (x − point) > 0, is not
/// drawn, so the inside of a closed chamber shows. Walls (polygons and meshes, opaque
/// and transparent) are clipped per pixel, so a cut shell shows its cut edge and its
/// inner face; a sphere is dropped whole when its centre lies beyond the plane (a ball
/// is shown entire or not at all, as a DEM post-processor's half-space selection).
/// With a wedge normal a second plane through the same point joins it and only what
/// lies beyond both is removed: a wedge, a quarter when the two normals are
/// perpendicular (the engineer's cut-away, which shows two sections and the
/// surfaces between them).
struct CutPlane {
  Vec3 point = Vec3::Zero();     // m, world: a point on the plane
  Vec3 normal = Vec3::UnitZ();   // world, any length > 0: points into the removed half-space
  std::optional<Vec3> wedge_normal;  // world, any length > 0: the second plane's, through point

  /// Whether x is removed: beyond the plane, and beyond the second one if any.
  bool removes(const Vec3& x) const {
    const Vec3 r = x - point;
    return r.dot(normal) > 0.0 && (!wedge_normal || r.dot(*wedge_normal) > 0.0);
  }
};

struct FrameDescription {
  std::vector<SphereInstance> spheres;
  std::vector<Polygon> polygons;
  std::vector<MeshInstance> meshes;
  Rgb background = kBackdrop;
  double time = 0.0;         // s, middle of the exposure (overlays, motion blur)
  std::uint64_t index = 0;   // frame number: seeds the sensor noise of this frame
  double lightGain = 1.0;    // lighting change: scales every lit colour and the background
  std::optional<CutPlane> cut;  // none: everything is drawn
};

}  // namespace rocklab::render
