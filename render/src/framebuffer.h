#pragma once
// The off-screen target: colour + depth renderbuffers, optionally multisampled
// (MSAA works on OSMesa only through an FBO, resolved by a blit: STACK.md §3).
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
  /// Resolves the samples and reads the pixels into `bgra` (CV_8UC4, reallocated
  /// if needed). GL row 0 goes to image row 0: the projection puts v = 0 there,
  /// so no flip is needed.
  void read(cv::Mat& bgra) const;

  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

 private:
  const GlApi& gl_;
  int width_, height_, samples_;
  GLuint drawFbo_ = 0, colour_ = 0, depth_ = 0;     // drawn into
  GLuint resolveFbo_ = 0, resolveColour_ = 0;       // MSAA only: single-sample copy
};

}  // namespace rocklab::render::detail
