#include "surface_pass.h"

#include <algorithm>

namespace rocklab::render::detail {

using geometry::Mat3;
using geometry::Vec3;

SurfacePass::SurfacePass(const GlApi& gl)
    : gl_(gl),
      program_(gl, kSurfaceVertexShader, kSurfaceFragmentShader, "surface"),
      uCameraFromModel_(program_.uniform("cameraFromModel")),
      uClip_(program_.uniform("clipFromCamera")),
      uColour_(program_.uniform("colour")),
      uLighting_(program_.uniform("lighting")),
      uGain_(program_.uniform("gain")) {
  gl.GenVertexArrays(1, &polygonVao_);
  gl.GenBuffers(1, &polygonVbo_);
  gl.BindVertexArray(polygonVao_);
  gl.BindBuffer(GL_ARRAY_BUFFER, polygonVbo_);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  gl.BindVertexArray(0);
  gl.check("surface pass setup");
}

SurfacePass::~SurfacePass() {
  for (auto& [key, mesh] : meshes_) release(mesh);
  gl_.DeleteBuffers(1, &polygonVbo_);
  gl_.DeleteVertexArrays(1, &polygonVao_);
}

void SurfacePass::release(CachedMesh& m) {
  gl_.DeleteBuffers(1, &m.vbo);
  gl_.DeleteBuffers(1, &m.ebo);
  gl_.DeleteVertexArrays(1, &m.vao);
}

const SurfacePass::CachedMesh& SurfacePass::cachedMesh(const std::shared_ptr<const geometry::TriangleMesh>& mesh) {
  auto it = meshes_.find(mesh.get());
  // A live entry is the same object (its address cannot be reused while it lives).
  if (it != meshes_.end() && !it->second.owner.expired()) return it->second;
  if (it != meshes_.end()) release(it->second);
  CachedMesh m;
  m.owner = mesh;
  std::vector<float> vertices;
  vertices.reserve(3 * mesh->vertices.size());
  for (const Vec3& v : mesh->vertices)
    for (int k = 0; k < 3; ++k) vertices.push_back(static_cast<float>(v[k]));
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * mesh->triangles.size());
  for (const auto& t : mesh->triangles) indices.insert(indices.end(), t.begin(), t.end());
  m.indexCount = static_cast<GLsizei>(indices.size());
  gl_.GenVertexArrays(1, &m.vao);
  gl_.GenBuffers(1, &m.vbo);
  gl_.GenBuffers(1, &m.ebo);
  gl_.BindVertexArray(m.vao);
  gl_.BindBuffer(GL_ARRAY_BUFFER, m.vbo);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)), vertices.data(),
                 GL_STATIC_DRAW);
  gl_.EnableVertexAttribArray(0);
  gl_.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  gl_.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ebo);
  gl_.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(std::uint32_t)),
                 indices.data(), GL_STATIC_DRAW);
  gl_.BindVertexArray(0);
  return meshes_[mesh.get()] = m;
}

void SurfacePass::prepare(const FrameDescription& frame, const Mat3& rotation, const Vec3& translation) {
  opaque_.clear();
  transparent_.clear();
  auto listDraw = [&](const Draw& d, float opacity) { (opacity < 1.0f ? transparent_ : opaque_).push_back(d); };

  // Polygons: fan-triangulated in the camera frame (double, then float).
  polygonVertices_.clear();
  for (const Polygon& p : frame.polygons) {
    const GLint first = static_cast<GLint>(polygonVertices_.size() / 3);
    Vec3 centroid = Vec3::Zero();
    std::vector<Vec3> cam;
    cam.reserve(p.vertices.size());
    for (const Vec3& v : p.vertices) {
      cam.push_back(rotation * v + translation);
      centroid += cam.back();
    }
    centroid /= static_cast<double>(cam.size());
    for (std::size_t k = 1; k + 1 < cam.size(); ++k)
      for (const Vec3* v : {&cam[0], &cam[k], &cam[k + 1]})
        for (int i = 0; i < 3; ++i) polygonVertices_.push_back(static_cast<float>((*v)[i]));
    const GLsizei count = static_cast<GLsizei>(polygonVertices_.size() / 3) - first;
    listDraw({polygonVao_, first, count, false, Eigen::Matrix4f::Identity(),
              {p.colour.r, p.colour.g, p.colour.b, p.opacity}, centroid.norm()},
             p.opacity);
  }
  gl_.BindBuffer(GL_ARRAY_BUFFER, polygonVbo_);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(polygonVertices_.size() * sizeof(float)),
                 polygonVertices_.data(), GL_STREAM_DRAW);

  // Meshes: cached model-frame buffers, placed by cameraFromModel.
  for (auto it = meshes_.begin(); it != meshes_.end();) {
    if (it->second.owner.expired()) {
      release(it->second);
      it = meshes_.erase(it);
    } else {
      ++it;
    }
  }
  for (const MeshInstance& m : frame.meshes) {
    const CachedMesh& cached = cachedMesh(m.mesh);
    const Mat3 r = rotation * m.rotation;
    const Vec3 t = rotation * m.translation + translation;
    const auto box = m.mesh->bounds();
    const Vec3 centre = r * (0.5 * (box.lo + box.hi)) + t;
    listDraw({cached.vao, 0, cached.indexCount, true, rigidMatrix(r, t),
              {m.colour.r, m.colour.g, m.colour.b, m.opacity}, centre.norm()},
             m.opacity);
  }
  // Transparent: far to near (stable: equal distances keep the input order).
  std::stable_sort(transparent_.begin(), transparent_.end(),
                   [](const Draw& a, const Draw& b) { return a.distance > b.distance; });
}

void SurfacePass::drawList(const std::vector<Draw>& draws, const ViewUniforms& view) const {
  if (draws.empty()) return;
  gl_.UseProgram(program_.id());
  gl_.UniformMatrix4fv(uClip_, 1, GL_FALSE, view.clipFromCamera.data());
  gl_.Uniform4f(uLighting_, view.lighting[0], view.lighting[1], view.lighting[2], view.lighting[3]);
  gl_.Uniform1f(uGain_, view.gain);
  for (const Draw& d : draws) {
    gl_.UniformMatrix4fv(uCameraFromModel_, 1, GL_FALSE, d.cameraFromModel.data());
    gl_.Uniform4f(uColour_, d.colour[0], d.colour[1], d.colour[2], d.colour[3]);
    gl_.BindVertexArray(d.vao);
    if (d.indexed)
      gl_.DrawElements(GL_TRIANGLES, d.count, GL_UNSIGNED_INT, nullptr);
    else
      gl_.DrawArrays(GL_TRIANGLES, d.first, d.count);
  }
  gl_.BindVertexArray(0);
}

void SurfacePass::drawOpaque(const ViewUniforms& view) const { drawList(opaque_, view); }
void SurfacePass::drawTransparent(const ViewUniforms& view) const { drawList(transparent_, view); }

}  // namespace rocklab::render::detail
