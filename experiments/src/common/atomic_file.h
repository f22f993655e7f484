#pragma once
// Text outputs (results.json, tables) are written to "<path>.partial" and renamed
// into place, so a half-written file never replaces a good one. Internal.
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace rocklab::experiments::detail {

inline void writeAtomically(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path tmp = path.string() + ".partial";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace rocklab::experiments::detail
