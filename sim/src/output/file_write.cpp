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

/// Writes `bytes` to the open `fd` of `temporary` (from its start, cutting off
/// anything beyond), closes it and renames it to `path`; on any failure removes
/// `temporary` and throws OutputError naming `path` and the system's reason.
void writeAndRename(int fd, const std::filesystem::path& temporary, const std::filesystem::path& path,
                    std::string_view bytes) {
  const auto fail = [&](int errnum) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return OutputError("cannot write '" + path.string() + "': " + systemReason(errnum));
  };
  // POSIX calls, not a stream: each failure keeps its errno (a stream's does not).
  if (!writeAll(fd, bytes) || ::ftruncate(fd, static_cast<off_t>(bytes.size())) != 0) {
    const int errnum = errno;
    ::close(fd);
    throw fail(errnum);
  }
  if (::close(fd) != 0) throw fail(errno);
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw fail(error.value());
}

}  // namespace

ReservedFile::ReservedFile(std::filesystem::path path, std::size_t bytes) : path_(std::move(path)) {
  const std::string partial = path_.string() + ".partial";
  fd_ = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ >= 0 && ::posix_fallocate(fd_, 0, static_cast<off_t>(bytes)) != 0) {
    ::close(fd_);  // no space even now: no reservation
    fd_ = -1;
    ::unlink(partial.c_str());
  }
}

ReservedFile::~ReservedFile() {
  if (fd_ < 0) return;
  ::close(fd_);
  ::unlink((path_.string() + ".partial").c_str());
}

void ReservedFile::write(std::string_view bytes) {
  if (fd_ < 0) {
    writeFileAtomically(path_, bytes);
    return;
  }
  const int fd = fd_;
  fd_ = -1;  // used: whatever happens, it is not removed twice
  writeAndRename(fd, path_.string() + ".partial", path_, bytes);
}

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
  const std::filesystem::path temporary = path.string() + ".partial";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw OutputError("cannot write '" + path.string() + "': " + systemReason(errno));
  writeAndRename(fd, temporary, path, bytes);
}

}  // namespace rocklab::sim::output
