#pragma once
// Frames → a movie file through OpenCV videoio (FFmpeg backend; GStreamer's
// writer fails here, STACK.md §4). Auto picks the first codec that opens:
// H.264 (avc1) in .mp4, MPEG-4 Part 2 (mp4v) in .mp4, Motion JPEG in .avi.
#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace rocklab::render {

enum class MovieCodec { Auto, H264, Mpeg4, Mjpeg };

class MovieWriter {
 public:
  /// `path` names the finished movie; its extension is set to the container of the
  /// codec used (.mp4 or .avi). Frames go to "<stem>.partial<ext>" until close().
  /// Throws std::runtime_error when no codec of the preference opens.
  MovieWriter(const std::filesystem::path& path, cv::Size frameSize, double fps,
              MovieCodec preferred = MovieCodec::Auto);
  ~MovieWriter();  // closes if still open; never throws
  MovieWriter(const MovieWriter&) = delete;
  MovieWriter& operator=(const MovieWriter&) = delete;

  /// Appends one 8-bit BGR frame of the constructor's size (throws otherwise).
  void write(const cv::Mat& bgr);
  /// Finishes the file and renames it into place; returns its path. Idempotent.
  std::filesystem::path close();

  MovieCodec codec() const { return codec_; }
  std::string codecName() const;  // e.g. "avc1 (H.264) in .mp4"
  const std::filesystem::path& path() const { return path_; }
  int framesWritten() const { return frames_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  MovieCodec codec_ = MovieCodec::Auto;
  std::filesystem::path path_, partial_;
  cv::Size size_;
  int frames_ = 0;
};

}  // namespace rocklab::render
