#include "camera/camera_recorder.h"

#include <cmath>
#include <cstdio>

#include "rocklab/render/image_io.h"
#include "rocklab/render/overlay.h"

namespace rocklab::experiments {

namespace {

std::string numbered(const std::string& stem, std::uint64_t k) {
  char name[64];
  std::snprintf(name, sizeof name, "_%06llu.png", static_cast<unsigned long long>(k));
  return stem + name;
}

}  // namespace

render::RenderOptions renderOptionsFor(const CameraSettings& c) {
  render::RenderOptions o;
  o.motionBlur = c.motion_blur;
  o.noiseSigma = c.noise_sigma;
  o.ambient = static_cast<float>(c.ambient);
  o.diffuse = static_cast<float>(c.diffuse);
  o.specular = static_cast<float>(c.specular);
  return o;
}

CameraRecorder::CameraRecorder(const CameraSettings& settings, const Scene& scene,
                               const std::filesystem::path& out_dir, std::ostream& log)
    : settings_(settings),
      out_dir_(out_dir),
      builder_(scene, settings.colour_by),
      renderer_(settings.camera, renderOptionsFor(settings)),
      next_still_(settings.start_time) {
  log << "  camera '" << settings_.name << "': " << settings_.camera.width << "x" << settings_.camera.height << " at "
      << settings_.camera.frameRate << " frames/s from t = " << settings_.start_time << " s; GL "
      << renderer_.glVersion() << ", " << renderer_.glRenderer() << (renderer_.coreProfile() ? "" : " (compatibility fallback)")
      << "\n";
  if (settings_.movie) {
    movie_ = std::make_unique<render::MovieWriter>(out_dir_ / (settings_.name + ".mp4"),
                                                   cv::Size(settings_.camera.width, settings_.camera.height),
                                                   settings_.movie_fps);
  }
}

bool CameraRecorder::due(double t) const {
  if (!inWindow(t)) return false;
  // Frame k belongs to start + k / frame_rate; due once t reaches it.
  const double next = settings_.start_time + static_cast<double>(frames_) / settings_.camera.frameRate;
  return t >= next - 1e-12;
}

void CameraRecorder::record(const sim::Snapshot& s, const sim::Model& model,
                            const std::unordered_set<std::uint64_t>& markers) {
  const auto t0 = std::chrono::steady_clock::now();
  render::FrameDescription frame = builder_.describe(s, model, markers, frames_);
  frame.lightGain = settings_.light_gain;
  frame.cut = settings_.cut;
  cv::Mat image = renderer_.render(frame);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (on_frame) on_frame(frames_, s.time, image);  // its time is the tracker's, not the camera's
  const auto t1 = std::chrono::steady_clock::now();
  if (settings_.all_frames) render::writePng(out_dir_ / "frames" / settings_.name / numbered("frame", frames_), image);
  const bool still = settings_.still_interval > 0 && s.time >= next_still_ - 1e-12;
  if (movie_ || still) {
    cv::Mat annotated = image.clone();
    if (settings_.timestamp) render::drawTimestamp(annotated, s.time);
    if (settings_.scale_bar) render::drawScaleBar(annotated, settings_.camera, settings_.scale_depth);
    if (movie_) movie_->write(annotated);
    if (still) {
      render::writePng(out_dir_ / numbered(settings_.name + "_still", stills_++), annotated);
      while (next_still_ <= s.time + 1e-12) next_still_ += settings_.still_interval;
    }
  }
  ++frames_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
}

void CameraRecorder::finish(nlohmann::json& cameras) {
  nlohmann::json c = {{"name", settings_.name},
                      {"frames", frames_},
                      {"stills", stills_},
                      {"resolution", {settings_.camera.width, settings_.camera.height}},
                      {"frame_rate", settings_.camera.frameRate},
                      {"gl_version", renderer_.glVersion()},
                      {"gl_renderer", renderer_.glRenderer()},
                      {"render_s", seconds_}};
  if (settings_.cut) {
    const auto& p = settings_.cut->point;
    const auto& n = settings_.cut->normal;
    c["cut"] = {{"point_m", {p.x(), p.y(), p.z()}}, {"normal", {n.x(), n.y(), n.z()}}};
    if (const auto& w = settings_.cut->wedge_normal) c["cut"]["wedge_normal"] = {w->x(), w->y(), w->z()};
  }
  if (movie_) {
    const std::filesystem::path path = movie_->close();
    c["movie"] = path.filename().string();
    c["movie_codec"] = movie_->codecName();
  }
  cameras.push_back(c);
}

}  // namespace rocklab::experiments
