#include "framebuffer.h"

#include <stdexcept>
#include <string>

namespace rocklab::render::detail {

namespace {

void requireComplete(const GlApi& gl, const char* which, int samples) {
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error(std::string("render: the ") + which + " framebuffer is incomplete (status " +
                             std::to_string(status) + ", " + std::to_string(samples) +
                             " samples; lower render options.msaaSamples)");
}

}  // namespace

Framebuffer::Framebuffer(const GlApi& gl, int width, int height, int samples)
    : gl_(gl), width_(width), height_(height), samples_(samples > 1 ? samples : 0) {
  gl.GenFramebuffers(1, &drawFbo_);
  gl.GenRenderbuffers(1, &colour_);
  gl.GenRenderbuffers(1, &depth_);
  gl.BindFramebuffer(GL_FRAMEBUFFER, drawFbo_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, colour_);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_RGBA8, width, height);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, depth_);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_DEPTH_COMPONENT24, width, height);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  requireComplete(gl, "drawing", samples_);
  if (samples_ > 0) {
    gl.GenFramebuffers(1, &resolveFbo_);
    gl.GenRenderbuffers(1, &resolveColour_);
    gl.BindFramebuffer(GL_FRAMEBUFFER, resolveFbo_);
    gl.BindRenderbuffer(GL_RENDERBUFFER, resolveColour_);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolveColour_);
    requireComplete(gl, "resolve", 0);
  }
  gl.check("framebuffer setup");
}

Framebuffer::~Framebuffer() {
  const GLuint fbos[] = {drawFbo_, resolveFbo_};
  const GLuint rbs[] = {colour_, depth_, resolveColour_};
  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl_.DeleteFramebuffers(2, fbos);
  gl_.DeleteRenderbuffers(3, rbs);
}

void Framebuffer::bindForDrawing() const {
  gl_.BindFramebuffer(GL_FRAMEBUFFER, drawFbo_);
  gl_.Viewport(0, 0, width_, height_);
}

void Framebuffer::read(cv::Mat& bgra) const {
  GLuint source = drawFbo_;
  if (samples_ > 0) {
    gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, drawFbo_);
    gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, resolveFbo_);
    gl_.BlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    source = resolveFbo_;
  }
  gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, source);
  gl_.ReadBuffer(GL_COLOR_ATTACHMENT0);
  bgra.create(height_, width_, CV_8UC4);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl_.ReadPixels(0, 0, width_, height_, GL_BGRA, GL_UNSIGNED_BYTE, bgra.data);
  gl_.check("reading the frame");
}

}  // namespace rocklab::render::detail
