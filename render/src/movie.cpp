#include "rocklab/render/movie.h"

#include <stdexcept>
#include <vector>

#include <opencv2/videoio.hpp>

namespace rocklab::render {

namespace {

struct CodecChoice {
  MovieCodec codec;
  char fourcc[5];
  const char* extension;
  const char* name;
};

constexpr CodecChoice kCodecs[] = {
    {MovieCodec::H264, "avc1", ".mp4", "avc1 (H.264) in .mp4"},
    {MovieCodec::Mpeg4, "mp4v", ".mp4", "mp4v (MPEG-4 Part 2) in .mp4"},
    {MovieCodec::Mjpeg, "MJPG", ".avi", "MJPG (Motion JPEG) in .avi"},
};

}  // namespace

struct MovieWriter::Impl {
  cv::VideoWriter writer;
};

MovieWriter::MovieWriter(const std::filesystem::path& path, cv::Size frameSize, double fps, MovieCodec preferred)
    : impl_(std::make_unique<Impl>()), size_(frameSize) {
  if (frameSize.width <= 0 || frameSize.height <= 0)
    throw std::runtime_error("MovieWriter " + path.string() + ": frame size must be positive");
  if (!(fps > 0.0)) throw std::runtime_error("MovieWriter " + path.string() + ": fps must be > 0");
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::string tried;
  for (const CodecChoice& c : kCodecs) {
    if (preferred != MovieCodec::Auto && preferred != c.codec) continue;
    std::filesystem::path finalPath = path;
    finalPath.replace_extension(c.extension);
    std::filesystem::path partial = path;
    partial.replace_extension(std::string(".partial") + c.extension);
    const int fourcc = cv::VideoWriter::fourcc(c.fourcc[0], c.fourcc[1], c.fourcc[2], c.fourcc[3]);
    // FFmpeg first; Motion JPEG also has OpenCV's own encoder.
    for (int api : {int(cv::CAP_FFMPEG), int(c.codec == MovieCodec::Mjpeg ? cv::CAP_OPENCV_MJPEG : -1)}) {
      if (api < 0) continue;
      try {
        impl_->writer.open(partial.string(), api, fourcc, fps, frameSize, true);
      } catch (const cv::Exception&) {
        impl_->writer.release();
      }
      if (impl_->writer.isOpened()) {
        codec_ = c.codec;
        path_ = finalPath;
        partial_ = partial;
        return;
      }
    }
    std::error_code ec;
    std::filesystem::remove(partial, ec);
    tried += std::string(tried.empty() ? "" : ", ") + c.name;
  }
  throw std::runtime_error("MovieWriter " + path.string() + ": no codec opened (tried " + tried + ")");
}

MovieWriter::~MovieWriter() {
  try {
    close();
  } catch (...) {
  }
}

void MovieWriter::write(const cv::Mat& bgr) {
  if (!impl_->writer.isOpened()) throw std::runtime_error("MovieWriter " + path_.string() + ": already closed");
  if (bgr.size() != size_ || bgr.type() != CV_8UC3)
    throw std::runtime_error("MovieWriter " + path_.string() + ": frame must be 8-bit BGR of " +
                             std::to_string(size_.width) + " x " + std::to_string(size_.height));
  impl_->writer.write(bgr);
  ++frames_;
}

std::filesystem::path MovieWriter::close() {
  if (impl_->writer.isOpened()) {
    impl_->writer.release();
    std::error_code ec;
    std::filesystem::rename(partial_, path_, ec);
    if (ec) throw std::runtime_error("MovieWriter " + path_.string() + ": cannot rename from " + partial_.string());
  }
  return path_;
}

std::string MovieWriter::codecName() const {
  for (const CodecChoice& c : kCodecs)
    if (c.codec == codec_) return c.name;
  return "none";
}

}  // namespace rocklab::render
