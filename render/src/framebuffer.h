#pragma once
// An off-screen target: colour (RGBA8, or RGBA32F for a layer kept in float) +
// depth (32-bit float) renderbuffers, optionally multisampled. MSAA works on OSMesa only through an FBO, resolved by
// a blit (STACK.md §3).
#include <opencv2/core.hpp>

#include "gl_api.h"

namespace rocklab::render::detail {

class Framebuffer {
 public:
  /// samples ≤ 1: single-sampled. Throws std::runtime_error if the FBO is incomplete.
  Framebuffer(const GlApi& gl, int width, int height, int samples, GLenum colourFormat = GL_RGBA8);
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  void bindForDrawing() const;
  /// Copies `buffers` (colour and depth, or one of them) into `target` (same size),
  /// resolving samples.
  void blitTo(const Framebuffer& target, GLbitfield buffers = GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT) const;
  /// Reads the pixels into `rgba`, reallocated if needed: CV_8UC4 (RGBA8, the
  /// renderbuffer's own channel order, so a plain copy) or CV_32FC4 (RGBA32F).
  /// Single-sampled only. GL row 0 goes to image row 0: the projection puts v = 0
  /// there, so no flip is needed.
  void read(cv::Mat& rgba) const;

  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

 private:
  const GlApi& gl_;
  int width_, height_, samples_;
  bool floatColour_;
  GLuint fbo_ = 0, colour_ = 0, depth_ = 0;
};

}  // namespace rocklab::render::detail
