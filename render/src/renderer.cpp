#include "rocklab/render/renderer.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "framebuffer.h"
#include "gl_api.h"
#include "gl_context.h"
#include "lens.h"
#include "sphere_pass.h"
#include "surface_pass.h"
#include "view.h"

namespace rocklab::render {

using namespace detail;

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

// Names the first bad entry of a frame description.
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
}

// splitmix64 finaliser: a well-mixed noise seed from (options seed, frame index).
std::uint64_t mix(std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = a ^ (b + 0x9e3779b97f4a7c15ull + (a << 6) + (a >> 2));
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace

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

int liveGlContexts() { return GlContext::liveCount(); }

struct Renderer::Impl {
  geometry::Camera camera;
  RenderOptions options;
  GlContext context;
  GlApi gl;
  std::string version, rendererName;
  std::unique_ptr<SpherePass> spheres;
  std::unique_ptr<SurfacePass> surfaces;
  LensWarp lens;
  std::unique_ptr<Framebuffer> target;
  cv::Mat bgra, sum, canvasBgr;  // scratch, reused between frames

  Impl(const geometry::Camera& cam, const RenderOptions& opts)
      : camera(cam), options(opts), context(opts.profile == GlProfile::Compatibility) {
    gl.load(context);
    auto text = [&](GLenum name) {
      const auto* s = reinterpret_cast<const char*>(gl.GetString(name));
      return std::string(s ? s : "");
    };
    version = text(GL_VERSION);
    rendererName = text(GL_RENDERER);
    int major = 0, minor = 0;
    if (std::sscanf(version.c_str(), "%d.%d", &major, &minor) != 2 || major * 10 + minor < 33)
      throw std::runtime_error("render: needs OpenGL 3.3, the OSMesa context gives '" + version + "'");
    spheres = std::make_unique<SpherePass>(gl);
    surfaces = std::make_unique<SurfacePass>(gl);
    applyCamera(cam, true);
  }

  ~Impl() {
    // GL objects are deleted in the context that owns them.
    context.makeCurrent();
    target.reset();
    surfaces.reset();
    spheres.reset();
  }

  void applyCamera(const geometry::Camera& cam, bool force) {
    const bool sameLens = cam.width == camera.width && cam.height == camera.height && cam.fx == camera.fx &&
                          cam.fy == camera.fy && cam.cx == camera.cx && cam.cy == camera.cy && cam.k1 == camera.k1 &&
                          cam.k2 == camera.k2;
    camera = cam;
    if (sameLens && !force) return;
    lens = makeLensWarp(camera);
    target.reset();
    target = std::make_unique<Framebuffer>(gl, lens.canvas.width, lens.canvas.height, options.msaaSamples);
  }

  // One undistorted canvas image (BGRA) with the spheres moved by velocity × dt.
  void drawCanvas(const FrameDescription& frame, const ViewUniforms& view, double dt) {
    spheres->upload(frame.spheres, camera.rotation, camera.translation, lens.canvas, options.nearClip, options.farClip, dt);
    target->bindForDrawing();
    const float g = view.gain;
    gl.ClearColor(std::min(1.0f, g * frame.background.r), std::min(1.0f, g * frame.background.g),
                  std::min(1.0f, g * frame.background.b), 1.0f);
    gl.ClearDepth(1.0);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    // 1. opaque walls
    gl.Disable(GL_BLEND);
    surfaces->drawOpaque(view);
    // 2. spheres, far to near, soft edges blended
    gl.Enable(GL_BLEND);
    gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    spheres->draw(view);
    // 3. transparent walls (Perspex), far to near, depth tested but not written
    gl.DepthMask(GL_FALSE);
    surfaces->drawTransparent(view);
    gl.DepthMask(GL_TRUE);
    target->read(bgra);
  }

  cv::Mat render(const FrameDescription& frame) {
    validateFrame(frame);
    context.makeCurrent();
    ViewUniforms view = makeViewUniforms(lens.canvas, options.nearClip, options.farClip);
    view.lighting = {options.ambient, options.diffuse, options.specular, options.shininess};
    view.gain = static_cast<float>(frame.lightGain);
    surfaces->prepare(frame, camera.rotation, camera.translation);

    // Exposure: subframes at the middles of n equal slices of the open shutter,
    // centred on frame.time, averaged (motion blur).
    const int n = options.motionBlur && camera.exposureTime > 0.0 ? options.motionBlurSubframes : 1;
    if (n == 1) {
      drawCanvas(frame, view, 0.0);
    } else {
      sum = cv::Mat::zeros(lens.canvas.height, lens.canvas.width, CV_32FC4);
      for (int s = 0; s < n; ++s) {
        drawCanvas(frame, view, camera.exposureTime * ((s + 0.5) / n - 0.5));
        cv::add(sum, bgra, sum, cv::noArray(), CV_32F);
      }
      sum.convertTo(bgra, CV_8U, 1.0 / n);
    }
    cv::Mat image;  // a new buffer every frame: the caller keeps it
    if (lens.active) {
      cv::cvtColor(bgra, canvasBgr, cv::COLOR_BGRA2BGR);
      applyLensWarp(lens, canvasBgr, image);
    } else {
      cv::cvtColor(bgra, image, cv::COLOR_BGRA2BGR);
    }

    // Sensor noise: Gaussian per channel, seeded by (noiseSeed, frame index).
    if (options.noiseSigma > 0.0) {
      cv::Mat noisy, noise(image.size(), CV_32FC3);
      cv::RNG rng(mix(options.noiseSeed, frame.index));
      rng.fill(noise, cv::RNG::NORMAL, 0.0, options.noiseSigma);
      image.convertTo(noisy, CV_32F);
      noisy += noise;
      noisy.convertTo(image, CV_8U);
    }
    return image;
  }
};

Renderer::Renderer(const geometry::Camera& camera, RenderOptions options) {
  camera.validate();
  options.validate();
  impl_ = std::make_unique<Impl>(camera, options);
}

Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

cv::Mat Renderer::render(const FrameDescription& frame) { return impl_->render(frame); }

void Renderer::setCamera(const geometry::Camera& camera) {
  camera.validate();
  impl_->context.makeCurrent();
  impl_->applyCamera(camera, false);
}

const geometry::Camera& Renderer::camera() const { return impl_->camera; }
const RenderOptions& Renderer::options() const { return impl_->options; }
std::string Renderer::glVersion() const { return impl_->version; }
std::string Renderer::glRenderer() const { return impl_->rendererName; }
bool Renderer::coreProfile() const { return impl_->context.coreProfile(); }

}  // namespace rocklab::render
