#pragma once
// JSON files: written (jsonText) and read back (readJsonFile). The text of a JSON
// output file (results.json, plan.json, study.json, ...). Paths
// go into these files, and a Linux path is bytes, not necessarily UTF-8: bytes that
// are not UTF-8 are written as U+FFFD instead of making the dump throw (which
// would lose the whole file). Internal.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace rocklab::experiments::detail {

/// A number for a JSON file: null where it is not finite (JSON has no NaN or infinity).
inline nlohmann::json finiteOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

inline std::string jsonText(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

/// A JSON file read back (a run's results.json, a set's plan.json), or a discarded
/// value when it is missing, not a regular file (a folder of that name), unreadable
/// or not JSON: reading a folder throws from inside the stream, so it is not opened.
inline nlohmann::json readJsonFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return nlohmann::json(nlohmann::json::value_t::discarded);
  try {
    std::ifstream in(path);
    return in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json(nlohmann::json::value_t::discarded);
  } catch (const std::exception&) {
    return nlohmann::json(nlohmann::json::value_t::discarded);
  }
}

}  // namespace rocklab::experiments::detail
