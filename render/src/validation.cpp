#include "validation.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "rocklab/render/renderer.h"

namespace rocklab::render {

namespace {

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

[[noreturn]] void invalidFrame(const std::string& field, const std::string& what) {
  throw std::invalid_argument("frame." + field + " " + what);
}

bool finiteColour(const Rgb& c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); }

}  // namespace

namespace detail {

void validateFrame(const FrameDescription& frame) {
  for (std::size_t i = 0; i < frame.spheres.size(); ++i) {
    const SphereInstance& s = frame.spheres[i];
    const std::string at = "spheres[" + std::to_string(i) + "].";
    if (!s.centre.allFinite()) invalidFrame(at + "centre", "must be finite");
    if (!(s.radius > 0.0) || !std::isfinite(s.radius)) invalidFrame(at + "radius", "must be > 0 m (got " + str(s.radius) + ")");
    if (!s.velocity.allFinite()) invalidFrame(at + "velocity", "must be finite");
    if (!finiteColour(s.colour)) invalidFrame(at + "colour", "must be finite");
  }
  for (std::size_t i = 0; i < frame.polygons.size(); ++i) {
    const Polygon& p = frame.polygons[i];
    const std::string at = "polygons[" + std::to_string(i) + "].";
    if (p.vertices.size() < 3) invalidFrame(at + "vertices", "needs at least 3 (got " + std::to_string(p.vertices.size()) + ")");
    for (const auto& v : p.vertices)
      if (!v.allFinite()) invalidFrame(at + "vertices", "must be finite");
    if (!(p.opacity >= 0.0f && p.opacity <= 1.0f)) invalidFrame(at + "opacity", "must be in [0, 1] (got " + str(p.opacity) + ")");
    if (!finiteColour(p.colour)) invalidFrame(at + "colour", "must be finite");
  }
  for (std::size_t i = 0; i < frame.meshes.size(); ++i) {
    const MeshInstance& m = frame.meshes[i];
    const std::string at = "meshes[" + std::to_string(i) + "].";
    if (!m.mesh) invalidFrame(at + "mesh", "is null");
    if (!m.rotation.allFinite() || !m.translation.allFinite()) invalidFrame(at + "rotation/translation", "must be finite");
    if (!(m.opacity >= 0.0f && m.opacity <= 1.0f)) invalidFrame(at + "opacity", "must be in [0, 1] (got " + str(m.opacity) + ")");
    if (!finiteColour(m.colour)) invalidFrame(at + "colour", "must be finite");
  }
  if (!(frame.lightGain >= 0.0) || !std::isfinite(frame.lightGain))
    invalidFrame("lightGain", "must be finite and >= 0 (got " + str(frame.lightGain) + ")");
  if (!finiteColour(frame.background)) invalidFrame("background", "must be finite");
  if (frame.cut) {
    if (!frame.cut->point.allFinite()) invalidFrame("cut.point", "must be finite");
    if (!frame.cut->normal.allFinite() || !(frame.cut->normal.norm() > 0.0))
      invalidFrame("cut.normal", "must be finite and non-zero");
    if (frame.cut->wedge_normal && (!frame.cut->wedge_normal->allFinite() || !(frame.cut->wedge_normal->norm() > 0.0)))
      invalidFrame("cut.wedge_normal", "must be finite and non-zero");
  }
}

}  // namespace detail

void RenderOptions::validate() const {
  auto bad = [](const std::string& field, const std::string& what) {
    throw std::invalid_argument("render options." + field + " " + what);
  };
  if (msaaSamples < 0 || msaaSamples > 16) bad("msaaSamples", "must be in [0, 16] (got " + std::to_string(msaaSamples) + ")");
  if (!(nearClip > 0.0) || !std::isfinite(nearClip)) bad("nearClip", "must be > 0 m (got " + str(nearClip) + ")");
  if (!(farClip > nearClip) || !std::isfinite(farClip)) bad("farClip", "must be finite and > nearClip (got " + str(farClip) + ")");
  for (auto [name, v] : {std::pair{"ambient", ambient}, {"diffuse", diffuse}, {"specular", specular}})
    if (!(v >= 0.0f) || !std::isfinite(v)) bad(name, "must be finite and >= 0 (got " + str(v) + ")");
  if (!(shininess >= 1.0f) || !std::isfinite(shininess)) bad("shininess", "must be >= 1 (got " + str(shininess) + ")");
  if (motionBlurSubframes < 1 || motionBlurSubframes > 256)
    bad("motionBlurSubframes", "must be in [1, 256] (got " + std::to_string(motionBlurSubframes) + ")");
  if (!(noiseSigma >= 0.0) || !std::isfinite(noiseSigma)) bad("noiseSigma", "must be >= 0 grey levels (got " + str(noiseSigma) + ")");
}

}  // namespace rocklab::render
