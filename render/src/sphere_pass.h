#pragma once
// Spheres as ray-cast impostors: cull against the canvas frustum and against each
// other (sphere_culling.h), bound each image by its exact bounding box cut down to
// the pixels where it can still show, draw far to near (so soft edges blend over
// what lies behind). Spheres whose box fits are
// point sprites (one primitive each: llvmpipe shades fewer 4×4 blocks than for two
// triangles); the rest (at the canvas border, or wider than the largest point) are
// instanced quads, drawn after the points.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "rocklab/render/frame.h"
#include "shaders.h"
#include "sphere_culling.h"
#include "surface_pass.h"
#include "view.h"

namespace rocklab::render::detail {

class SpherePass {
 public:
  explicit SpherePass(const GlApi& gl);
  ~SpherePass();
  SpherePass(const SpherePass&) = delete;
  SpherePass& operator=(const SpherePass&) = delete;

  /// Moves each centre by velocity × dt (motion-blur subframes; dt = 0 otherwise),
  /// drops the spheres whose (moved) centre lies beyond the cut, transforms to the
  /// camera frame (double), culls, sorts, uploads; and finds out whether every sphere
  /// in view lies beyond each of `screens` (behindScreens()).
  void upload(const std::vector<SphereInstance>& spheres, const geometry::Mat3& rotation,
              const geometry::Vec3& translation, const Canvas& canvas, double nearClip, double farClip, double dt,
              const std::optional<CutPlane>& cut = std::nullopt, const std::vector<Screen>& screens = {});
  /// After upload(): every sphere in view lies beyond every screen, up to a contact
  /// overlap (it reaches at most kScreenOverlap of its radius through the plane).
  bool behindScreens() const { return behindScreens_; }
  static constexpr double kScreenOverlap = 0.1;
  void draw(const ViewUniforms& view, const Canvas& canvas) const;

 private:
  struct Instance {        // 36 bytes per sphere on the GPU
    float sphere[4];       // camera-frame centre, radius (m)
    float box[4];          // image bounding box incl. soft edge: u0, v0, u1, v1 (canvas pixels)
    std::uint8_t rgba[4];  // colour, a unused
  };
  struct Key {
    double power;          // |c|² − r², m²: visibility order, near first
    std::uint32_t index;   // into staged_; tie-break
  };
  void setAttributes(GLuint vao, std::size_t firstInstance, GLuint divisor) const;

  const GlApi& gl_;
  Program program_;
  GLint uCanvasSize_, uAsQuads_, uPixelToRay_, uWindowDepth_, uLighting_, uGain_;
  GLuint pointVao_ = 0, quadVao_ = 0, vbo_ = 0;
  float maxPointSize_ = 1.0f;
  struct Staging {  // one chunk of the sphere list, staged on its own thread
    std::vector<Key> keys;
    std::vector<CameraSphere> staged;
    std::vector<std::array<std::uint8_t, 4>> colours;
    bool behindScreens = true;
    std::vector<Instance> points, quads;  // this chunk of the far-to-near order
  };
  std::vector<Staging> chunks_;
  std::vector<Key> keys_;
  std::vector<CameraSphere> staged_;
  std::vector<std::array<std::uint8_t, 4>> colours_;
  std::vector<std::uint32_t> order_;
  std::vector<Instance> instances_;
  SphereCuller culler_;
  std::size_t points_ = 0, quads_ = 0;
  bool behindScreens_ = true;
};

}  // namespace rocklab::render::detail
