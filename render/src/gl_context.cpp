#include "gl_context.h"

#include <atomic>
#include <stdexcept>

#include <GL/osmesa.h>

namespace rocklab::render::detail {

namespace {
std::atomic<int> g_live{0};
}

GlContext::GlContext(bool compatibilityOnly) {
  if (!compatibilityOnly) {
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 0,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                           OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    context_ = OSMesaCreateContextAttribs(attribs, nullptr);
    core_ = context_ != nullptr;
  }
  if (!context_) context_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (!context_) throw std::runtime_error("render: OSMesa could not create a GL context (core 3.3 nor compatibility)");
  ++g_live;
  makeCurrent();
}

GlContext::~GlContext() {
  if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(context_)) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
  --g_live;
}

void GlContext::makeCurrent() {
  auto* ctx = static_cast<OSMesaContext>(context_);
  if (OSMesaGetCurrentContext() == ctx) return;
  if (!OSMesaMakeCurrent(ctx, pixel_, GL_UNSIGNED_BYTE, 1, 1))
    throw std::runtime_error("render: OSMesaMakeCurrent failed");
}

GlProc GlContext::procAddress(const char* name) const {
  return OSMesaGetProcAddress(name);
}

int GlContext::liveCount() { return g_live.load(); }

}  // namespace rocklab::render::detail
