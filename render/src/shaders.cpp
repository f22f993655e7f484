#include "shaders.h"

#include <stdexcept>
#include <vector>

namespace rocklab::render::detail {

// Shared conventions (view.cpp, "camera → GL"): positions arrive in the camera
// frame (x right, y down, z forward, metres); gl_FragCoord.xy = (u + 0.5, v + 0.5)
// with (u, v) the OpenCV pixel on the canvas (surfaces get there through
// clipFromCamera, spheres through their pixel boxes); z_ndc = depthMap.x +
// depthMap.y / z for both, so spheres and walls share one depth buffer.

const char* const kSphereVertexShader = R"(#version 330 core
// Per instance: the sphere and its image's bounding box, computed on the CPU.
layout(location = 0) in vec4 centreRadius;  // camera frame: centre (m), radius (m)
layout(location = 1) in vec4 box;           // canvas pixels: u0, v0, u1, v1 (soft edge included)
layout(location = 2) in vec4 colour;        // rgb, unused
uniform vec2 canvasSize;                    // pixels
uniform int asQuads;                        // 0: one point per sphere, 1: a 4-vertex strip per sphere
flat out vec4 vSphere;
flat out vec3 vColour;
flat out float vInverseRadius;
// Pixel (u, v) → NDC: the pixel centre is at window (u + 0.5, v + 0.5), see view.cpp.
vec2 ndc(vec2 pixel) { return 2.0 * (pixel + 0.5) / canvasSize - 1.0; }
void main() {
  if (asQuads == 0) {
    // Square point sprite around the box: llvmpipe rasterises it as one primitive.
    gl_Position = vec4(ndc(0.5 * (box.xy + box.zw)), 0.0, 1.0);
    gl_PointSize = max(box.z - box.x, box.w - box.y);
  } else {
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
    gl_Position = vec4(ndc(mix(box.xy - 0.5, box.zw + 0.5, corner)), 0.0, 1.0);
  }
  vSphere = centreRadius;
  vColour = colour.rgb;
  vInverseRadius = 1.0 / centreRadius.w;
}
)";

const char* const kSphereFragmentShader = R"(#version 330 core
flat in vec4 vSphere;
flat in vec3 vColour;
flat in float vInverseRadius;
uniform vec4 pixelToRay;   // ray (x, y, 1) through window point w: x = w.x pixelToRay.x + pixelToRay.z, y likewise
uniform vec2 windowDepth;  // window depth of camera depth z: windowDepth.x + windowDepth.y / z
uniform vec4 lighting;     // ambient, diffuse, specular, shininess
uniform float gain;
out vec4 fragColour;
// Few divisions and roots (llvmpipe runs this for every pixel of every sphere's box,
// and takes an inverse root as a root and a division): three of each, and one more root.
void main() {
  vec3 c = vSphere.xyz;
  float r = vSphere.w;
  // The ray through this pixel's centre, p = t d (d.z = 1, so t is the depth z).
  vec3 d = vec3(gl_FragCoord.xy * pixelToRay.xy + pixelToRay.zw, 1.0);
  float rootD = sqrt(dot(d, d));
  // Distance of the ray from the centre, |c x d| / |d|: no cancellation, unlike
  // |c|^2 - (c.d)^2/|d|^2, so far, small spheres keep sub-pixel edges in float.
  float h = length(cross(c, d)) / rootD;
  // Coverage from the signed distance to the silhouette in pixels (h - r over the
  // screen-space gradient of h): a one-pixel ramp centred on the exact edge. (Not
  // from h^2: its finite-difference gradient is a tenth off on a small sphere, which
  // would widen the ramp beyond the half pixel the culler allows for.)
  vec2 gradient = vec2(dFdx(h), dFdy(h));
  float coverage = clamp(0.5 - (h - r) * inversesqrt(max(dot(gradient, gradient), 1e-30)), 0.0, 1.0);
  if (coverage <= 0.0) discard;
  // Nearest hit (beyond the silhouette, the tangent point): t |d| = c.d/|d| - s with
  // s = sqrt(r^2 - h^2), so the window depth a + b/t = a + b |d|^2 / (c.d - s |d|).
  float s = sqrt(max(r * r - h * h, 0.0));
  float depth = windowDepth.x + windowDepth.y * (rootD * rootD) / (dot(c, d) - s * rootD);
  // With the light at the eye, n.l = n.v = n.h = sqrt(1 - (h/r)^2) = s / r.
  // Blinn-Phong's highlight x^n (x = n.h) as (1 - n (1 - x) / 4)^4: both are
  // exp(-n (1 - x)) near the peak (same half width), without pow's exp2/log2,
  // which cost 11 % of a frame under llvmpipe.
  float ndv = s * vInverseRadius;
  float highlight = max(1.0 - 0.25 * lighting.w * (1.0 - ndv), 0.0);
  highlight *= highlight;
  highlight *= highlight;
  vec3 lit = vColour * (lighting.x + lighting.y * ndv) + vec3(lighting.z * highlight);
  // Clamped here, as the core profile's blending clamps it for the 8-bit target (the
  // compatibility profile clamps it once more elsewhere, a level apart now and then).
  fragColour = vec4(min(gain * lit, vec3(1.0)), coverage);
  gl_FragDepth = depth;
}
)";

const char* const kSurfaceVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;  // model frame (m)
layout(location = 1) in vec3 normal;    // model frame, unit: the face normal (flat shading)
uniform mat4 cameraFromModel;           // rigid
uniform mat4 clipFromCamera;
out vec3 vCamera;
flat out vec3 vNormal;
void main() {
  vec4 pc = cameraFromModel * vec4(position, 1.0);
  vCamera = pc.xyz;
  vNormal = mat3(cameraFromModel) * normal;
  gl_Position = clipFromCamera * pc;
}
)";

const char* const kSurfaceFragmentShader = R"(#version 330 core
in vec3 vCamera;
flat in vec3 vNormal;
uniform vec4 colour;    // rgb, opacity
uniform vec4 lighting;  // ambient, diffuse, specular, shininess
uniform float gain;
uniform vec4 cutPlane;  // camera frame: discarded where dot(n, x) + d > 0; (0, 0, 0, -1) = no cut
uniform vec4 cutWedge;  // the same, and discarded only where beyond both; (0, 0, 0, 1) = no wedge
out vec4 fragColour;
void main() {
  if (dot(cutPlane.xyz, vCamera) + cutPlane.w > 0.0 && dot(cutWedge.xyz, vCamera) + cutWedge.w > 0.0) discard;
  // Two-sided; headlight, so n.l = n.v = n.h.
  float ndv = abs(dot(vNormal, normalize(-vCamera)));
  float highlight = max(1.0 - 0.25 * lighting.w * (1.0 - ndv), 0.0);  // x^n, as for spheres
  highlight *= highlight;
  highlight *= highlight;
  vec3 lit = colour.rgb * (lighting.x + lighting.y * ndv) + vec3(lighting.z * highlight);
  // Clamped as an 8-bit target's blending clamps it, so a float target (the screen
  // layer, screen_layer.h) gets the same.
  fragColour = vec4(min(gain * lit, vec3(1.0)), colour.a);
}
)";

namespace {

GLuint compile(const GlApi& gl, GLenum kind, const char* source, const std::string& name) {
  const GLuint shader = gl.CreateShader(kind);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = GL_FALSE;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    gl.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(length) + 1, '\0');
    gl.GetShaderInfoLog(shader, length, nullptr, log.data());
    gl.DeleteShader(shader);
    throw std::runtime_error("render: " + name + (kind == GL_VERTEX_SHADER ? " vertex" : " fragment") +
                             " shader does not compile: " + log.data());
  }
  return shader;
}

}  // namespace

Program::Program(const GlApi& gl, const char* vertexSource, const char* fragmentSource, const char* name)
    : gl_(gl), name_(name) {
  const GLuint vs = compile(gl, GL_VERTEX_SHADER, vertexSource, name_);
  GLuint fs = 0;
  try {
    fs = compile(gl, GL_FRAGMENT_SHADER, fragmentSource, name_);
  } catch (...) {
    gl.DeleteShader(vs);
    throw;
  }
  id_ = gl.CreateProgram();
  gl.AttachShader(id_, vs);
  gl.AttachShader(id_, fs);
  gl.LinkProgram(id_);
  gl.DeleteShader(vs);
  gl.DeleteShader(fs);
  GLint ok = GL_FALSE;
  gl.GetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    gl.GetProgramiv(id_, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(length) + 1, '\0');
    gl.GetProgramInfoLog(id_, length, nullptr, log.data());
    gl.DeleteProgram(id_);
    throw std::runtime_error("render: " + name_ + " program does not link: " + log.data());
  }
}

Program::~Program() { gl_.DeleteProgram(id_); }

GLint Program::uniform(const char* name) const {
  const GLint location = gl_.GetUniformLocation(id_, name);
  if (location < 0) throw std::runtime_error("render: " + name_ + " program has no uniform " + name);
  return location;
}

}  // namespace rocklab::render::detail
