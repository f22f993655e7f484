#pragma once
// Spheres as instanced ray-cast impostors: cull against the canvas frustum and
// against each other (sphere_culling.h), draw far to near (so soft edges blend
// over what lies behind).
#include <array>
#include <cstdint>
#include <vector>

#include "rocklab/render/frame.h"
#include "shaders.h"
#include "sphere_culling.h"
#include "view.h"

namespace rocklab::render::detail {

class SpherePass {
 public:
  explicit SpherePass(const GlApi& gl);
  ~SpherePass();
  SpherePass(const SpherePass&) = delete;
  SpherePass& operator=(const SpherePass&) = delete;

  /// Moves each centre by velocity × dt (motion-blur subframes; dt = 0 otherwise),
  /// transforms to the camera frame (double), culls, sorts, uploads.
  void upload(const std::vector<SphereInstance>& spheres, const geometry::Mat3& rotation,
              const geometry::Vec3& translation, const Canvas& canvas, double nearClip, double farClip, double dt);
  void draw(const ViewUniforms& view) const;
  std::size_t drawnCount() const { return instances_.size(); }
  /// Spheres inside the view that the occlusion test dropped in the last upload.
  std::size_t occludedCount() const { return occluded_; }

 private:
  struct Instance {        // 20 bytes per sphere on the GPU
    float centre[3];       // camera frame, m
    float radius;          // m
    std::uint8_t rgba[4];  // colour, a unused
  };
  struct Key {
    double power;          // |c|² − r², m²: visibility order, near first
    std::uint32_t index;   // into staged_; tie-break
  };
  const GlApi& gl_;
  Program program_;
  GLint uClip_, uIntrinsics_, uDepthMap_, uLighting_, uGain_;
  GLuint vao_ = 0, vbo_ = 0;
  std::vector<Key> keys_;
  std::vector<CameraSphere> staged_;
  std::vector<std::array<std::uint8_t, 4>> colours_;
  std::vector<std::uint32_t> order_;
  std::vector<Instance> instances_;
  SphereCuller culler_;
  std::size_t occluded_ = 0;
};

}  // namespace rocklab::render::detail
