#pragma once
// Text outputs (results.json, tables) are written to "<path>.partial" and renamed
// into place, so a half-written file never replaces a good one; a failure throws
// sim::output::OutputError naming the file and the system's reason. Internal.
#include <filesystem>
#include <string>

#include "rocklab/sim/output/file_write.h"

namespace rocklab::experiments::detail {

inline void writeAtomically(const std::filesystem::path& path, const std::string& text) {
  sim::output::writeFileAtomically(path, text);
}

}  // namespace rocklab::experiments::detail
