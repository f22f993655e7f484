#include "rocklab/sim/output/file_write.h"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <system_error>

namespace rocklab::sim::output {

std::string systemReason(int errnum) {
  std::string text = std::strerror(errnum);
  if (!text.empty()) text[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
  return text;
}

namespace {

/// Writes every byte to `fd`; false with errno set when the system refuses.
bool writeAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t written = ::write(fd, bytes.data(), bytes.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    bytes.remove_prefix(static_cast<std::size_t>(written));
  }
  return true;
}

}  // namespace

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
  const std::filesystem::path temporary = path.string() + ".partial";
  const auto fail = [&](int errnum) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return OutputError("cannot write '" + path.string() + "': " + systemReason(errnum));
  };
  // POSIX calls, not a stream: each failure keeps its errno (a stream's does not).
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw fail(errno);
  if (!writeAll(fd, bytes)) {
    const int errnum = errno;
    ::close(fd);
    throw fail(errnum);
  }
  if (::close(fd) != 0) throw fail(errno);
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw fail(error.value());
}

}  // namespace rocklab::sim::output
