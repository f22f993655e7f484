#pragma once
// Polygons (walls) and triangle meshes (mesh walls): opaque ones before the
// spheres, transparent ones (opacity < 1) after them, far to near, no depth writes.
#include <memory>
#include <unordered_map>
#include <vector>

#include "rocklab/render/frame.h"
#include "shaders.h"
#include "view.h"

namespace rocklab::render::detail {

class SurfacePass {
 public:
  explicit SurfacePass(const GlApi& gl);
  ~SurfacePass();
  SurfacePass(const SurfacePass&) = delete;
  SurfacePass& operator=(const SurfacePass&) = delete;

  /// Uploads this frame's polygons (camera frame, one buffer), makes sure every
  /// mesh has a cached buffer (dropping those of meshes that no longer exist),
  /// and lists the draws.
  void prepare(const FrameDescription& frame, const geometry::Mat3& rotation, const geometry::Vec3& translation);
  void drawOpaque(const ViewUniforms& view) const;
  void drawTransparent(const ViewUniforms& view) const;

 private:
  struct Draw {
    GLuint vao;
    GLint first;                     // first vertex (polygons)
    GLsizei count;                   // vertices or indices
    bool indexed;                    // meshes: glDrawElements
    Eigen::Matrix4f cameraFromModel;
    std::array<float, 4> colour;     // rgb, opacity
    double distance;                 // m, to the camera (transparent sort)
  };
  struct CachedMesh {
    std::weak_ptr<const geometry::TriangleMesh> owner;
    GLuint vao = 0, vbo = 0, ebo = 0;
    GLsizei indexCount = 0;
  };
  const CachedMesh& cachedMesh(const std::shared_ptr<const geometry::TriangleMesh>& mesh);
  void release(CachedMesh& m);
  void drawList(const std::vector<Draw>& draws, const ViewUniforms& view) const;

  const GlApi& gl_;
  Program program_;
  GLint uCameraFromModel_, uClip_, uColour_, uLighting_, uGain_;
  GLuint polygonVao_ = 0, polygonVbo_ = 0;
  std::vector<float> polygonVertices_;
  std::unordered_map<const geometry::TriangleMesh*, CachedMesh> meshes_;
  std::vector<Draw> opaque_, transparent_;
};

}  // namespace rocklab::render::detail
