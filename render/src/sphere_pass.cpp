#include "sphere_pass.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>

namespace rocklab::render::detail {

namespace {

std::uint8_t toByte(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

}  // namespace

SpherePass::SpherePass(const GlApi& gl)
    : gl_(gl),
      program_(gl, kSphereVertexShader, kSphereFragmentShader, "sphere"),
      uClip_(program_.uniform("clipFromCamera")),
      uIntrinsics_(program_.uniform("intrinsics")),
      uDepthMap_(program_.uniform("depthMap")),
      uLighting_(program_.uniform("lighting")),
      uGain_(program_.uniform("gain")) {
  gl.GenVertexArrays(1, &vao_);
  gl.GenBuffers(1, &vbo_);
  gl.BindVertexArray(vao_);
  gl.BindBuffer(GL_ARRAY_BUFFER, vbo_);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(Instance), reinterpret_cast<const void*>(offsetof(Instance, centre)));
  gl.VertexAttribDivisor(0, 1);
  gl.EnableVertexAttribArray(1);
  gl.VertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(Instance), reinterpret_cast<const void*>(offsetof(Instance, rgba)));
  gl.VertexAttribDivisor(1, 1);
  gl.BindVertexArray(0);
  gl.check("sphere pass setup");
}

SpherePass::~SpherePass() {
  gl_.DeleteBuffers(1, &vbo_);
  gl_.DeleteVertexArrays(1, &vao_);
}

void SpherePass::upload(const std::vector<SphereInstance>& spheres, const geometry::Mat3& rotation,
                        const geometry::Vec3& translation, const Canvas& canvas, double nearClip, double farClip,
                        double dt) {
  // Side planes of the canvas frustum (through the eye, two pixels outside the
  // canvas edges), inward unit normals: a sphere with n·c < −r is invisible.
  const double xl = (-2.5 - canvas.cx) / canvas.fx, xr = (canvas.width + 1.5 - canvas.cx) / canvas.fx;
  const double yt = (-2.5 - canvas.cy) / canvas.fy, yb = (canvas.height + 1.5 - canvas.cy) / canvas.fy;
  const std::array<geometry::Vec3, 4> planes{geometry::Vec3(1, 0, -xl).normalized(), geometry::Vec3(-1, 0, xr).normalized(),
                                             geometry::Vec3(0, 1, -yt).normalized(), geometry::Vec3(0, -1, yb).normalized()};
  keys_.clear();
  staged_.clear();
  colours_.clear();
  for (const SphereInstance& s : spheres) {
    const geometry::Vec3 c = rotation * (s.centre + dt * s.velocity) + translation;
    const double r = s.radius;
    // Not drawn: crossing the near plane (the impostor needs the eye outside), wholly beyond far, outside the sides.
    if (c.z() - r < nearClip || c.z() - r > farClip) continue;
    bool outside = false;
    for (const auto& n : planes) outside = outside || n.dot(c) < -r;
    if (outside) continue;
    keys_.push_back({c.squaredNorm() - r * r, static_cast<std::uint32_t>(staged_.size())});
    staged_.push_back({static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()), static_cast<float>(r)});
    colours_.push_back({toByte(s.colour.r), toByte(s.colour.g), toByte(s.colour.b), 255});
  }
  // Near to far for the occlusion test, then drawn far to near.
  std::sort(keys_.begin(), keys_.end(),
            [](const Key& a, const Key& b) { return a.power != b.power ? a.power < b.power : a.index < b.index; });
  order_.resize(keys_.size());
  for (std::size_t k = 0; k < keys_.size(); ++k) order_[k] = keys_[k].index;
  const std::vector<std::uint8_t>& visible = culler_.cull(staged_, order_, canvas);
  instances_.clear();
  for (auto k = order_.rbegin(); k != order_.rend(); ++k)
    if (visible[*k]) {
      const CameraSphere& s = staged_[*k];
      instances_.push_back({{s.x, s.y, s.z}, s.radius, {colours_[*k][0], colours_[*k][1], colours_[*k][2], colours_[*k][3]}});
    }
  occluded_ = staged_.size() - instances_.size();
  if (getenv("RL_DEBUG")) fprintf(stderr, "in view %zu drawn %zu\n", staged_.size(), instances_.size());
  gl_.BindBuffer(GL_ARRAY_BUFFER, vbo_);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(instances_.size() * sizeof(Instance)), instances_.data(),
                 GL_STREAM_DRAW);
}

void SpherePass::draw(const ViewUniforms& view) const {
  if (instances_.empty()) return;
  gl_.UseProgram(program_.id());
  gl_.UniformMatrix4fv(uClip_, 1, GL_FALSE, view.clipFromCamera.data());
  gl_.Uniform4f(uIntrinsics_, view.intrinsics[0], view.intrinsics[1], view.intrinsics[2], view.intrinsics[3]);
  gl_.Uniform2f(uDepthMap_, view.depthMap[0], view.depthMap[1]);
  gl_.Uniform4f(uLighting_, view.lighting[0], view.lighting[1], view.lighting[2], view.lighting[3]);
  gl_.Uniform1f(uGain_, view.gain);
  gl_.BindVertexArray(vao_);
  gl_.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(instances_.size()));
  gl_.BindVertexArray(0);
}

}  // namespace rocklab::render::detail
