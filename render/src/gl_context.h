#pragma once
// An OSMesa GL context with no window system. The only file that includes
// <GL/osmesa.h>; everything else calls GL through the table in gl_api.h, whose
// pointers come from OSMesaGetProcAddress, so the link order against libGL or
// libOpenGL cannot break rendering (STACK.md §3).
#include <string>

namespace rocklab::render::detail {

using GlProc = void (*)();

class GlContext {
 public:
  /// Tries a 3.3 core profile (unless compatibilityOnly), then a compatibility
  /// context. Throws std::runtime_error when neither can be created.
  explicit GlContext(bool compatibilityOnly);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// Binds the context to the calling thread (cheap when it already is).
  void makeCurrent();
  GlProc procAddress(const char* name) const;
  bool coreProfile() const { return core_; }

  static int liveCount();

 private:
  void* context_ = nullptr;          // OSMesaContext
  unsigned char pixel_[4] = {};      // 1×1 default framebuffer: we draw into FBOs
  bool core_ = false;
};

}  // namespace rocklab::render::detail
