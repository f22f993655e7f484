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

/// Disk space set aside when a run starts for a small file written at its end
/// (results.json): "<path>.partial" is allocated now, so a disk that fills up
/// during the run still takes the file that says so. Without the space the
/// reservation is simply not made and write() tries like writeFileAtomically.
class ReservedFile {
 public:
  ReservedFile(std::filesystem::path path, std::size_t bytes);
  ~ReservedFile();  // removes the reservation if write() did not use it
  ReservedFile(const ReservedFile&) = delete;
  ReservedFile& operator=(const ReservedFile&) = delete;
  /// Writes `bytes` over the reservation (beyond it, as far as the disk allows)
  /// and renames it to the path; throws OutputError like writeFileAtomically.
  void write(std::string_view bytes);

 private:
  std::filesystem::path path_;
  int fd_ = -1;  // the reserved "<path>.partial", open while unused
};

/// The system's text for an errno value, starting lower case ("no space left on device").
std::string systemReason(int errnum);

}  // namespace rocklab::sim::output
