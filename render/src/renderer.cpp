#include "rocklab/render/renderer.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "framebuffer.h"
#include "gl_api.h"
#include "gl_context.h"
#include "lens.h"
#include "screen_layer.h"
#include "sensor.h"
#include "sphere_pass.h"
#include "surface_pass.h"
#include "validation.h"
#include "view.h"

namespace rocklab::render {

using namespace detail;

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
  // Targets, all canvas-sized: `opaque` holds the background and the opaque walls
  // (drawn through `multisampled` when MSAA is on) and is redrawn only when they
  // change; each frame starts from a copy of it in `target`.
  // `screens` holds the transparent walls when every sphere lies beyond them.
  std::unique_ptr<Framebuffer> target, opaque, multisampled;
  std::unique_ptr<ScreenLayer> screens;
  std::vector<double> opaqueKey;  // what `opaque` shows; empty = nothing yet
  int samples = 0;                // MSAA samples used: options.msaaSamples, at most GL_MAX_SAMPLES
  cv::Mat rgba, sum, canvasBgr;   // scratch, reused between frames
  bool laidOver = false;          // the last frame's transparent walls went through `screens`

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
    GLint maxSamples = 0;
    gl.GetIntegerv(GL_MAX_SAMPLES, &maxSamples);
    samples = std::min(options.msaaSamples, static_cast<int>(maxSamples));
    spheres = std::make_unique<SpherePass>(gl);
    surfaces = std::make_unique<SurfacePass>(gl);
    applyCamera(cam, true);
  }

  ~Impl() {
    // GL objects are deleted in the context that owns them.
    context.makeCurrent();
    target.reset();
    opaque.reset();
    multisampled.reset();
    screens.reset();
    surfaces.reset();
    spheres.reset();
  }

  void applyCamera(const geometry::Camera& cam, bool force) {
    const bool sameLens = cam.width == camera.width && cam.height == camera.height && cam.fx == camera.fx &&
                          cam.fy == camera.fy && cam.cx == camera.cx && cam.cy == camera.cy && cam.k1 == camera.k1 &&
                          cam.k2 == camera.k2;
    camera = cam;
    opaqueKey.clear();
    if (sameLens && !force) return;
    lens = makeLensWarp(camera);
    const int w = lens.canvas.width, h = lens.canvas.height;
    target.reset();
    opaque.reset();
    multisampled.reset();
    screens.reset();
    target = std::make_unique<Framebuffer>(gl, w, h, 0);
    opaque = std::make_unique<Framebuffer>(gl, w, h, 0);
    if (samples > 1) multisampled = std::make_unique<Framebuffer>(gl, w, h, samples);
  }

  // Background and opaque walls, antialiased by MSAA; redrawn only when they changed.
  void updateOpaqueLayer(const FrameDescription& frame, const ViewUniforms& view) {
    std::vector<double> key = surfaces->opaqueSignature();
    key.insert(key.end(), {frame.background.r, frame.background.g, frame.background.b, view.gain});
    key.insert(key.end(), view.cutPlane.begin(), view.cutPlane.end());
    key.insert(key.end(), view.cutWedge.begin(), view.cutWedge.end());
    if (key == opaqueKey) return;
    const Framebuffer& layer = multisampled ? *multisampled : *opaque;
    layer.bindForDrawing();
    const float g = view.gain;
    gl.ClearColor(std::min(1.0f, g * frame.background.r), std::min(1.0f, g * frame.background.g),
                  std::min(1.0f, g * frame.background.b), 1.0f);
    gl.ClearDepth(1.0);
    gl.DepthMask(GL_TRUE);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.Disable(GL_BLEND);
    surfaces->drawOpaque(view);
    if (multisampled) multisampled->blitTo(*opaque);
    opaqueKey = std::move(key);
  }

  // One undistorted canvas image (RGBA) with the spheres moved by velocity × dt.
  void drawCanvas(const FrameDescription& frame, const ViewUniforms& view, double dt) {
    spheres->upload(frame.spheres, camera.rotation, camera.translation, lens.canvas, options.nearClip, options.farClip, dt,
                    frame.cut, surfaces->screens());
    const bool screensOnCpu = !surfaces->screens().empty() && spheres->behindScreens();
    laidOver = laidOver && screensOnCpu;
    // 1. opaque walls: a copy of the cached layer (colour and depth)
    opaque->blitTo(*target);
    target->bindForDrawing();
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    // 2. spheres, far to near, soft edges blended
    gl.Enable(GL_BLEND);
    gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    spheres->draw(view, lens.canvas);
    // 3. transparent walls (Perspex), far to near, depth tested but not written; or,
    // when every sphere lies beyond them, their layer laid over the image.
    if (!screensOnCpu) {
      gl.DepthMask(GL_FALSE);
      surfaces->drawTransparent(view);
      gl.DepthMask(GL_TRUE);
    }
    target->read(rgba);
    if (screensOnCpu) {
      if (!screens) screens = std::make_unique<ScreenLayer>(gl, lens.canvas.width, lens.canvas.height);
      std::vector<double> key = opaqueKey;
      key.insert(key.end(), surfaces->transparentSignature().begin(), surfaces->transparentSignature().end());
      screens->update(key, *opaque, *surfaces, view);
      screens->composite(rgba);
    }
  }

  cv::Mat render(const FrameDescription& frame) {
    validateFrame(frame);
    context.makeCurrent();
    ViewUniforms view = makeViewUniforms(lens.canvas, options.nearClip, options.farClip);
    view.lighting = {options.ambient, options.diffuse, options.specular, options.shininess};
    view.gain = static_cast<float>(frame.lightGain);
    if (frame.cut) {
      // A plane in the camera frame: n_c = R n (unit), d = −n_c · (R p + t).
      const auto inCamera = [&](const geometry::Vec3& normal) {
        const geometry::Vec3 n = camera.rotation * normal.normalized();
        const double d = -n.dot(camera.rotation * frame.cut->point + camera.translation);
        return std::array<float, 4>{static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z()),
                                    static_cast<float>(d)};
      };
      view.cutPlane = inCamera(frame.cut->normal);
      if (frame.cut->wedge_normal) view.cutWedge = inCamera(*frame.cut->wedge_normal);
    }
    surfaces->prepare(frame, camera.rotation, camera.translation);
    updateOpaqueLayer(frame, view);
    laidOver = true;  // until a subframe blends its transparent walls in GL

    // Exposure: subframes at the middles of n equal slices of the open shutter,
    // centred on frame.time, averaged (motion blur).
    const int n = options.motionBlur && camera.exposureTime > 0.0 ? options.motionBlurSubframes : 1;
    if (n == 1) {
      drawCanvas(frame, view, 0.0);
    } else {
      sum = cv::Mat::zeros(lens.canvas.height, lens.canvas.width, CV_32FC4);
      for (int s = 0; s < n; ++s) {
        drawCanvas(frame, view, camera.exposureTime * ((s + 0.5) / n - 0.5));
        cv::add(sum, rgba, sum, cv::noArray(), CV_32F);
      }
      sum.convertTo(rgba, CV_8U, 1.0 / n);
    }
    cv::Mat image;  // a new buffer every frame: the caller keeps it
    if (lens.active) {
      cv::cvtColor(rgba, canvasBgr, cv::COLOR_RGBA2BGR);
      applyLensWarp(lens, canvasBgr, image);
    } else {
      cv::cvtColor(rgba, image, cv::COLOR_RGBA2BGR);
    }

    if (options.noiseSigma > 0.0) addSensorNoise(image, options.noiseSigma, options.noiseSeed, frame.index);
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
bool Renderer::transparentWallsLaidOver() const { return impl_->laidOver; }

}  // namespace rocklab::render
