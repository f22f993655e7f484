#include "framebuffer.h"

#include <stdexcept>
#include <string>

namespace rocklab::render::detail {

Framebuffer::Framebuffer(const GlApi& gl, int width, int height, int samples, GLenum colourFormat)
    : gl_(gl),
      width_(width),
      height_(height),
      samples_(samples > 1 ? samples : 0),
      floatColour_(colourFormat == GL_RGBA32F) {
  gl.GenFramebuffers(1, &fbo_);
  gl.GenRenderbuffers(1, &colour_);
  gl.GenRenderbuffers(1, &depth_);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, colour_);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, colourFormat, width, height);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, depth_);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_DEPTH_COMPONENT32F, width, height);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("render: a " + std::to_string(width) + " x " + std::to_string(height) +
                             " framebuffer with " + std::to_string(samples_) + " samples is incomplete (status " +
                             std::to_string(status) + "; lower render options.msaaSamples)");
  gl.check("framebuffer setup");
}

Framebuffer::~Framebuffer() {
  const GLuint rbs[] = {colour_, depth_};
  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl_.DeleteFramebuffers(1, &fbo_);
  gl_.DeleteRenderbuffers(2, rbs);
}

void Framebuffer::bindForDrawing() const {
  gl_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  gl_.Viewport(0, 0, width_, height_);
}

void Framebuffer::blitTo(const Framebuffer& target, GLbitfield buffers) const {
  gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, target.fbo_);
  gl_.BlitFramebuffer(0, 0, width_, height_, 0, 0, target.width_, target.height_, buffers, GL_NEAREST);
  gl_.check("blitting a framebuffer");
}

void Framebuffer::read(cv::Mat& rgba) const {
  gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  gl_.ReadBuffer(GL_COLOR_ATTACHMENT0);
  rgba.create(height_, width_, floatColour_ ? CV_32FC4 : CV_8UC4);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl_.ReadPixels(0, 0, width_, height_, GL_RGBA, floatColour_ ? GL_FLOAT : GL_UNSIGNED_BYTE, rgba.data);
  gl_.check("reading the frame");
}

}  // namespace rocklab::render::detail
