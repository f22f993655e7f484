#pragma once
// GLSL sources of the two programs and a small compile/link helper.
#include <string>

#include "gl_api.h"

namespace rocklab::render::detail {

// Sphere impostors: a point sprite (or a quad) per instance, ray-cast per fragment.
extern const char* const kSphereVertexShader;
extern const char* const kSphereFragmentShader;
// Polygons and meshes: flat-shaded triangles (a face normal per vertex).
extern const char* const kSurfaceVertexShader;
extern const char* const kSurfaceFragmentShader;

/// A linked program; throws std::runtime_error with the compiler log on failure.
class Program {
 public:
  Program(const GlApi& gl, const char* vertexSource, const char* fragmentSource, const char* name);
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  GLuint id() const { return id_; }
  /// Location of a uniform; throws when the program has no active uniform of that name.
  GLint uniform(const char* name) const;

 private:
  const GlApi& gl_;
  GLuint id_ = 0;
  std::string name_;
};

}  // namespace rocklab::render::detail
