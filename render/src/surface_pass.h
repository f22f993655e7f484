#pragma once
// Polygons (walls) and triangle meshes (mesh walls), flat shaded. Opaque ones
// form the background layer (drawn once while they do not change, see
// renderer.cpp); transparent ones (opacity < 1) are drawn after the spheres, far
// to near, without depth writes.
#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "rocklab/render/frame.h"
#include "shaders.h"
#include "view.h"

namespace rocklab::render::detail {

/// The plane of a flat transparent wall in the camera frame, oriented away from the
/// eye: a point x lies beyond it (on the far side) when normal · x + offset > 0.
struct Screen {
  geometry::Vec3 normal;  // unit
  double offset;          // m, < 0 (the eye is on the near side)
};

class SurfacePass {
 public:
  explicit SurfacePass(const GlApi& gl);
  ~SurfacePass();
  SurfacePass(const SurfacePass&) = delete;
  SurfacePass& operator=(const SurfacePass&) = delete;

  /// Uploads this frame's polygons (camera frame, one buffer), makes sure every
  /// mesh has a cached buffer (dropping those of meshes that no longer exist),
  /// lists the draws, and records the opaque signature.
  void prepare(const FrameDescription& frame, const geometry::Mat3& rotation, const geometry::Vec3& translation);
  void drawOpaque(const ViewUniforms& view) const;
  void drawTransparent(const ViewUniforms& view) const;
  /// Everything the opaque layer depends on, in camera frame (equal ⇒ same pixels).
  const std::vector<double>& opaqueSignature() const { return signature_; }
  /// The same for the transparent walls.
  const std::vector<double>& transparentSignature() const { return transparentSignature_; }
  /// The transparent walls' planes, when every one is a flat polygon the eye does not
  /// lie in (a transparent mesh, or none: empty).
  const std::vector<Screen>& screens() const { return screens_; }

 private:
  struct Draw {
    GLuint vao;
    GLint first;                     // first vertex
    GLsizei count;                   // vertices
    Eigen::Matrix4f cameraFromModel;
    std::array<float, 4> colour;     // rgb, opacity
    double distance;                 // m, to the camera (transparent sort)
  };
  struct CachedMesh {
    std::weak_ptr<const geometry::TriangleMesh> owner;
    std::uint64_t generation = 0;    // distinguishes meshes that reused an address
    GLuint vao = 0, vbo = 0;
    GLsizei vertexCount = 0;
  };
  const CachedMesh& cachedMesh(const std::shared_ptr<const geometry::TriangleMesh>& mesh);
  void release(CachedMesh& m);
  void drawList(const std::vector<Draw>& draws, const ViewUniforms& view) const;
  static void setAttributes(const GlApi& gl, GLuint vao, GLuint vbo);

  const GlApi& gl_;
  Program program_;
  GLint uCameraFromModel_, uClip_, uColour_, uLighting_, uGain_, uCutPlane_, uCutWedge_;
  GLuint polygonVao_ = 0, polygonVbo_ = 0;
  std::vector<float> polygonVertices_;  // x y z nx ny nz per vertex, camera frame
  std::unordered_map<const geometry::TriangleMesh*, CachedMesh> meshes_;
  std::uint64_t meshGeneration_ = 0;
  std::vector<Draw> opaque_, transparent_;
  std::vector<double> signature_, transparentSignature_;
  std::vector<Screen> screens_;
};

}  // namespace rocklab::render::detail
