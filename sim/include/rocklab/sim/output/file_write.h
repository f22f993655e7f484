#pragma once
// Outputs written whole (results.json, tables, the .pvd list, checkpoint.h5 built
// in memory) go to "<path>.partial" and are renamed over <path>, so a half-written file never replaces
// a good one. A failure (a full disk) removes the temporary and says which file
// and why, in the system's words.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace rocklab::sim::output {

/// An output that could not be written: the message names the file and the reason.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws OutputError, e.g. "cannot write 'out/results.json': no space left on device".
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

/// The system's text for an errno value, starting lower case ("no space left on device").
std::string systemReason(int errnum);

}  // namespace rocklab::sim::output
