#pragma once
// One scene camera during a run: renders a frame at each of its frame times
// (the first step at or after k / frame_rate), appends it to the movie, writes
// PNG stills (and every frame when asked), and reports what it did. The GL
// context is created here, so a scene without cameras never has one.
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <unordered_set>

#include "camera/frame_builder.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/render/movie.h"
#include "rocklab/render/renderer.h"

namespace rocklab::experiments {

/// The render options a camera's settings ask for (motion blur, sensor noise).
render::RenderOptions renderOptionsFor(const CameraSettings& c);

class CameraRecorder {
 public:
  CameraRecorder(const CameraSettings& settings, const Scene& scene, const std::filesystem::path& out_dir,
                 std::ostream& log);
  /// True when a frame is due at simulated time t.
  bool due(double t) const;
  /// True when t lies within the camera's start_time..end_time.
  bool inWindow(double t) const { return t >= settings_.start_time && t <= settings_.end_time; }
  void record(const sim::Snapshot& s, const sim::Model& model, const std::unordered_set<std::uint64_t>& markers);
  /// Closes the movie; adds this camera's figures to `cameras` (a JSON array).
  void finish(nlohmann::json& cameras);
  double seconds() const { return seconds_; }
  const CameraSettings& settings() const { return settings_; }
  /// Called with every raw frame (no overlays), e.g. for marker tracking.
  std::function<void(std::uint64_t frame, double time, const cv::Mat& raw)> on_frame;

 private:
  CameraSettings settings_;
  std::filesystem::path out_dir_;
  FrameBuilder builder_;
  render::Renderer renderer_;
  std::unique_ptr<render::MovieWriter> movie_;
  std::uint64_t frames_ = 0, stills_ = 0;
  double next_still_ = 0.0;
  double seconds_ = 0.0;  // wall time spent rendering and writing
};

}  // namespace rocklab::experiments
