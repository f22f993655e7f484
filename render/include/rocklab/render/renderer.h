#pragma once
// Off-screen renderer (OSMesa, no display): a FrameDescription seen through a
// geometry::Camera → an 8-bit BGR cv::Mat.
//
// Constructing a Renderer creates its GL context; nothing in this library creates
// one earlier (a scene without a camera never pays for GL). One Renderer is used by
// one thread at a time; several Renderers may coexist.
//
// What is drawn, in order:
//   1. background and opaque polygons and meshes (depth test, MSAA); kept as a
//      layer and redrawn only when they, the camera or the gain change;
//   2. spheres as ray-cast impostors (exact silhouettes, depth via gl_FragDepth,
//      edges antialiased in the shader from the distance to the silhouette), far
//      to near so the soft edges blend over what lies behind; spheres wholly
//      hidden behind nearer spheres are dropped on the CPU first;
//   3. transparent polygons and meshes (opacity < 1, the Perspex), far to near,
//      depth tested, no depth writes.
// A cut-away (FrameDescription::cut) discards wall pixels beyond its plane (beyond
// both, for a wedge) in the surface shader and drops the spheres whose centre lies
// in the removed part before culling.
// Lighting: Blinn–Phong with a headlight at the camera plus ambient.
// Lens distortion (camera k1, k2): the scene is rendered undistorted on a canvas
// large enough for the distorted field of view, then warped with cv::remap, so
// pixels land where cv::projectPoints puts them.
// Camera → GL: the projection keeps OpenCV's y-down pixel rows (image row v is
// GL window row v, pixel centre at (u + 0.5, v + 0.5)), so glReadPixels returns
// the image top row first and no flip is needed.
#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/render/frame.h"

namespace rocklab::render {

enum class GlProfile {
  PreferCore,     // GL 3.3 core profile; compatibility context if that fails
  Compatibility,  // compatibility context only (for testing the fallback)
};

struct RenderOptions {
  // GL and quality.
  GlProfile profile = GlProfile::PreferCore;
  int msaaSamples = 4;        // multisampling of opaque wall edges: 0 or 1 = off; lowered to GL_MAX_SAMPLES (4 on llvmpipe)
  double nearClip = 0.01;     // m, spheres crossing it are not drawn
  double farClip = 100.0;     // m
  // Lighting (fractions of the material colour; the specular highlight is white).
  float ambient = 0.35f;
  float diffuse = 0.65f;
  float specular = 0.20f;
  float shininess = 40.0f;
  // Lab realism, all off by default.
  bool motionBlur = false;    // average subframes over camera.exposureTime (sphere velocities)
  int motionBlurSubframes = 8;
  double noiseSigma = 0.0;    // grey levels (8-bit), Gaussian sensor noise per channel; 0 = off
  std::uint64_t noiseSeed = 1;  // mixed with FrameDescription::index

  /// Throws std::invalid_argument naming the field ("render options.msaaSamples ...").
  void validate() const;
};

class Renderer {
 public:
  /// Validates camera and options, creates the GL context. Throws
  /// std::invalid_argument for bad input, std::runtime_error when GL fails.
  Renderer(const geometry::Camera& camera, RenderOptions options = {});
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws one frame: BGR, 8 bits per channel, camera.height × camera.width.
  /// Deterministic: the same frame (and options) gives the same bytes.
  cv::Mat render(const FrameDescription& frame);

  /// Replaces the camera (pose, intrinsics or resolution; validated).
  void setCamera(const geometry::Camera& camera);
  const geometry::Camera& camera() const;
  const RenderOptions& options() const;

  std::string glVersion() const;   // e.g. "4.5 (Core Profile) Mesa 22.3.6"
  std::string glRenderer() const;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  bool coreProfile() const;        // false when the compatibility fallback was taken
  /// Whether the last frame laid its transparent walls over on the CPU (in every
  /// motion-blur subframe every sphere in view lay beyond them: render/src/screen_layer.h)
  /// instead of blending them in GL.
  bool transparentWallsLaidOver() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Number of GL contexts alive in this process (0 until a Renderer is made).
int liveGlContexts();

}  // namespace rocklab::render
