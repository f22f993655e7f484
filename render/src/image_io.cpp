#include "rocklab/render/image_io.h"

#include <fstream>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace rocklab::render {

void writePng(const std::filesystem::path& path, const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U)
    throw std::runtime_error("writePng " + path.string() + ": needs a non-empty 8-bit image");
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error("writePng " + path.string() + ": PNG encoding failed");
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::filesystem::path partial = path;
  partial += ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw std::runtime_error("writePng " + partial.string() + ": cannot write");
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) throw std::runtime_error("writePng " + path.string() + ": cannot rename from .partial: " + ec.message());
}

}  // namespace rocklab::render
