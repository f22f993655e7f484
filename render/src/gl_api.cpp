#include "gl_api.h"

#include <cstdio>
#include <stdexcept>
#include <string>

namespace rocklab::render::detail {

void GlApi::load(const GlContext& context) {
#define ROCKLAB_GL_LOAD(type, name)                                                      \
  name = reinterpret_cast<type>(context.procAddress("gl" #name));                        \
  if (!name) throw std::runtime_error("render: the GL context has no gl" #name);
  ROCKLAB_GL_FUNCTIONS(ROCKLAB_GL_LOAD)
#undef ROCKLAB_GL_LOAD
}

void GlApi::check(const char* where) const {
  const GLenum e = GetError();
  if (e == GL_NO_ERROR) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", e);
  throw std::runtime_error(std::string("render: GL error ") + code + " in " + where);
}

}  // namespace rocklab::render::detail
