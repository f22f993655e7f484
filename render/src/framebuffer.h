#pragma once
// An off-screen target: colour (RGBA8) + depth (32-bit float) renderbuffers,
// optionally multisampled. MSAA works on OSMesa only through an FBO, resolved by
// a blit (STACK.md §3).
#include <opencv2/core.hpp>

#include "gl_api.h"

namespace rocklab::render::detail {

class Framebuffer {
 public:
  /// samples ≤ 1: single-sampled. Throws std::runtime_error if the FBO is incomplete.
  Framebuffer(const GlApi& gl, int width, int height, int samples);
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  void bindForDrawing() const;
  /// Copies colour and depth into `target` (same size), resolving samples.
  void blitTo(const Framebuffer& target) const;
  /// Reads the pixels into `bgra` (CV_8UC4, reallocated if needed); single-sampled
  /// only. GL row 0 goes to image row 0: the projection puts v = 0 there, so no
  /// flip is needed.
  void read(cv::Mat& bgra) const;

  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

 private:
  const GlApi& gl_;
  int width_, height_, samples_;
  GLuint fbo_ = 0, colour_ = 0, depth_ = 0;
};

}  // namespace rocklab::render::detail
