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
  std::filesystem::path partial = path;
  partial += ".partial";
  // Every failure names the file and leaves neither a half-written target nor a .partial.
  auto fail = [&](const std::string& why) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw std::runtime_error("writePng " + path.string() + ": " + why);
  };
  std::error_code ec;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), ec);
  if (ec) fail("cannot create its folder: " + ec.message());
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) fail("cannot write " + partial.string());
  }
  std::filesystem::rename(partial, path, ec);
  if (ec) fail("cannot rename from .partial: " + ec.message());
}

}  // namespace rocklab::render
