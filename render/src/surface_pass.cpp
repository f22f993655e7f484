#include "surface_pass.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rocklab::render::detail {

using geometry::Mat3;
using geometry::Vec3;

namespace {

void pushVertex(std::vector<float>& out, const Vec3& p, const Vec3& n) {
  for (int i = 0; i < 3; ++i) out.push_back(static_cast<float>(p[i]));
  for (int i = 0; i < 3; ++i) out.push_back(static_cast<float>(n[i]));
}

// Unit normal of a planar polygon by Newell's method (any vertex order, robust to
// collinear neighbours); zero for a degenerate polygon.
Vec3 newellNormal(const std::vector<Vec3>& p) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) n += p[i].cross(p[(i + 1) % p.size()]);
  return n.norm() > 0 ? Vec3(n.normalized()) : n;
}

}  // namespace

void SurfacePass::setAttributes(const GlApi& gl, GLuint vao, GLuint vbo) {
  gl.BindVertexArray(vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  gl.EnableVertexAttribArray(1);
  gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<const void*>(3 * sizeof(float)));
  gl.BindVertexArray(0);
}

SurfacePass::SurfacePass(const GlApi& gl)
    : gl_(gl),
      program_(gl, kSurfaceVertexShader, kSurfaceFragmentShader, "surface"),
      uCameraFromModel_(program_.uniform("cameraFromModel")),
      uClip_(program_.uniform("clipFromCamera")),
      uColour_(program_.uniform("colour")),
      uLighting_(program_.uniform("lighting")),
      uGain_(program_.uniform("gain")),
      uCutPlane_(program_.uniform("cutPlane")),
      uCutWedge_(program_.uniform("cutWedge")) {
  gl.GenVertexArrays(1, &polygonVao_);
  gl.GenBuffers(1, &polygonVbo_);
  setAttributes(gl, polygonVao_, polygonVbo_);
  gl.check("surface pass setup");
}

SurfacePass::~SurfacePass() {
  for (auto& [key, mesh] : meshes_) release(mesh);
  gl_.DeleteBuffers(1, &polygonVbo_);
  gl_.DeleteVertexArrays(1, &polygonVao_);
}

void SurfacePass::release(CachedMesh& m) {
  gl_.DeleteBuffers(1, &m.vbo);
  gl_.DeleteVertexArrays(1, &m.vao);
}

const SurfacePass::CachedMesh& SurfacePass::cachedMesh(const std::shared_ptr<const geometry::TriangleMesh>& mesh) {
  auto it = meshes_.find(mesh.get());
  // A live entry is the same object (its address cannot be reused while it lives).
  if (it != meshes_.end() && !it->second.owner.expired()) return it->second;
  if (it != meshes_.end()) release(it->second);
  // Flat shading: three vertices of their own per triangle, each with the face normal.
  std::vector<float> vertices;
  vertices.reserve(18 * mesh->triangles.size());
  for (const auto& t : mesh->triangles) {
    for (std::uint32_t i : t)
      if (i >= mesh->vertices.size())
        throw std::invalid_argument("frame.meshes: a triangle refers to vertex " + std::to_string(i) + " of " +
                                    std::to_string(mesh->vertices.size()));
    const Vec3 &a = mesh->vertices[t[0]], &b = mesh->vertices[t[1]], &c = mesh->vertices[t[2]];
    const Vec3 cross = (b - a).cross(c - a);
    const Vec3 n = cross.norm() > 0 ? Vec3(cross.normalized()) : Vec3::Zero();
    for (const Vec3* p : {&a, &b, &c}) pushVertex(vertices, *p, n);
  }
  CachedMesh m;
  m.owner = mesh;
  m.generation = ++meshGeneration_;
  m.vertexCount = static_cast<GLsizei>(vertices.size() / 6);
  gl_.GenVertexArrays(1, &m.vao);
  gl_.GenBuffers(1, &m.vbo);
  gl_.BindBuffer(GL_ARRAY_BUFFER, m.vbo);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)), vertices.data(),
                 GL_STATIC_DRAW);
  setAttributes(gl_, m.vao, m.vbo);
  return meshes_[mesh.get()] = m;
}

void SurfacePass::prepare(const FrameDescription& frame, const Mat3& rotation, const Vec3& translation) {
  opaque_.clear();
  transparent_.clear();
  signature_.clear();
  transparentSignature_.clear();
  screens_.clear();
  bool flatScreens = true;
  // Signatures: the opaque draws' and the transparent draws' values, apart.
  bool opaqueDraw = true;
  auto sign = [&](std::initializer_list<double> values) {
    auto& to = opaqueDraw ? signature_ : transparentSignature_;
    to.insert(to.end(), values);
  };
  auto listDraw = [&](const Draw& d) {
    (opaqueDraw ? opaque_ : transparent_).push_back(d);
    sign({d.colour[0], d.colour[1], d.colour[2], d.colour[3]});
  };

  // Polygons: fan-triangulated in the camera frame (double, then float).
  polygonVertices_.clear();
  for (const Polygon& p : frame.polygons) {
    const GLint first = static_cast<GLint>(polygonVertices_.size() / 6);
    std::vector<Vec3> cam;
    cam.reserve(p.vertices.size());
    Vec3 centroid = Vec3::Zero();
    for (const Vec3& v : p.vertices) {
      cam.push_back(rotation * v + translation);
      centroid += cam.back();
    }
    centroid /= static_cast<double>(cam.size());
    const Vec3 n = newellNormal(cam);
    for (std::size_t k = 1; k + 1 < cam.size(); ++k)
      for (const Vec3* v : {&cam[0], &cam[k], &cam[k + 1]}) pushVertex(polygonVertices_, *v, n);
    const GLsizei count = static_cast<GLsizei>(polygonVertices_.size() / 6) - first;
    opaqueDraw = p.opacity >= 1.0f;
    for (const Vec3& v : cam) sign({v.x(), v.y(), v.z()});
    if (!opaqueDraw) {
      // Its plane through the centroid, turned away from the eye (the origin). An eye
      // within a micrometre of the plane sees the wall edge-on: no screen then.
      const double offset = -n.dot(centroid);
      if (std::abs(offset) > 1e-6 && n.norm() > 0.0)
        screens_.push_back(offset < 0.0 ? Screen{n, offset} : Screen{-n, -offset});
      else
        flatScreens = false;
    }
    listDraw({polygonVao_, first, count, Eigen::Matrix4f::Identity(), {p.colour.r, p.colour.g, p.colour.b, p.opacity},
              centroid.norm()});
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
    const Eigen::Matrix4f cameraFromModel = rigidMatrix(r, t);
    opaqueDraw = m.opacity >= 1.0f;
    flatScreens = flatScreens && opaqueDraw;
    sign({static_cast<double>(cached.generation)});
    for (int i = 0; i < 16; ++i) sign({cameraFromModel.data()[i]});
    listDraw({cached.vao, 0, cached.vertexCount, cameraFromModel, {m.colour.r, m.colour.g, m.colour.b, m.opacity},
              centre.norm()});
  }
  if (!flatScreens) screens_.clear();
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
  gl_.Uniform4f(uCutPlane_, view.cutPlane[0], view.cutPlane[1], view.cutPlane[2], view.cutPlane[3]);
  gl_.Uniform4f(uCutWedge_, view.cutWedge[0], view.cutWedge[1], view.cutWedge[2], view.cutWedge[3]);
  for (const Draw& d : draws) {
    gl_.UniformMatrix4fv(uCameraFromModel_, 1, GL_FALSE, d.cameraFromModel.data());
    gl_.Uniform4f(uColour_, d.colour[0], d.colour[1], d.colour[2], d.colour[3]);
    gl_.BindVertexArray(d.vao);
    gl_.DrawArrays(GL_TRIANGLES, d.first, d.count);
  }
  gl_.BindVertexArray(0);
}

void SurfacePass::drawOpaque(const ViewUniforms& view) const { drawList(opaque_, view); }
void SurfacePass::drawTransparent(const ViewUniforms& view) const { drawList(transparent_, view); }

}  // namespace rocklab::render::detail
