#pragma once
// Writing frames to disk.
#include <filesystem>

#include <opencv2/core.hpp>

namespace rocklab::render {

/// Writes `image` (8-bit BGR, BGRA or grey) as PNG atomically: the bytes go to
/// "<path>.partial", which is then renamed to `path`, so a reader never sees a
/// half-written frame. Creates missing parent folders. Throws std::runtime_error
/// naming the path on failure.
void writePng(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace rocklab::render
