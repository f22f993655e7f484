// HDF5 failures in words a user can act on: the C library clears its error
// stack at its next call (a destructor on the way to the catch is one), so the
// system's reason (errno: "No space left on device") is recorded when the call
// fails, by the library's own error callback.
#include <H5Cpp.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cctype>
#include <string>
#include <vector>

#include "hdf5_io.h"

namespace rocklab::sim::output::detail {

namespace {

thread_local std::string g_system_reason;  // of the last failed call, "" when none

struct Watched {
  int* fd;
  std::string diverted;  // why it was diverted, "" while it is not
};
thread_local std::vector<Watched> g_watched;  // files being written (watchForFailure)

/// Points every watched file's descriptor at an anonymous in-memory file. A
/// file-size limit (RLIMIT_FSIZE, EFBIG) would refuse those writes too: its soft
/// value is lifted to the hard one, for good (the run is failing anyway).
void divertWatched(const std::string& reason) {
  bool any = false;
  for (Watched& w : g_watched) {
    if (!w.diverted.empty()) continue;
    const int scratch = ::memfd_create("rocklab-failed-hdf5", MFD_CLOEXEC);
    if (scratch < 0) continue;
    ::dup2(scratch, *w.fd);
    ::close(scratch);
    w.diverted = reason;
    any = true;
  }
  rlimit size{};
  if (any && ::getrlimit(RLIMIT_FSIZE, &size) == 0 && size.rlim_cur < size.rlim_max) {
    size.rlim_cur = size.rlim_max;
    ::setrlimit(RLIMIT_FSIZE, &size);
  }
}

/// The text of "error message = '...'" that HDF5 adds to a failed system call.
herr_t findSystemReason(unsigned, const H5E_error2_t* error, void* found) {
  auto& reason = *static_cast<std::string*>(found);
  if (!reason.empty() || error->desc == nullptr) return 0;
  const std::string desc = error->desc;
  const std::string marker = "error message = '";
  const auto start = desc.find(marker);
  if (start == std::string::npos) return 0;
  const auto end = desc.find('\'', start + marker.size());
  reason = desc.substr(start + marker.size(), end == std::string::npos ? std::string::npos : end - start - marker.size());
  if (!reason.empty()) reason[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(reason[0])));
  return 0;
}

herr_t recordFailure(hid_t stack, void*) {
  std::string reason;
  H5Ewalk2(stack, H5E_WALK_DOWNWARD, findSystemReason, &reason);
  if (reason.empty()) return 0;
  g_system_reason = reason;
  divertWatched(reason);  // inside the failing call: before any close can fail
  return 0;
}

}  // namespace

void watchForFailure(int* fd) {
  g_watched.push_back({fd, {}});
}

void unwatch(int* fd) {
  std::erase_if(g_watched, [fd](const Watched& w) { return w.fd == fd; });
}

std::string diverted(int* fd) {
  for (const Watched& w : g_watched)
    if (w.fd == fd) return w.diverted;
  return {};
}

void recordHdf5Errors() {
  H5Eset_auto2(H5E_DEFAULT, recordFailure, nullptr);
}

std::string hdf5Failure(const H5::Exception& e) {
  std::string what = e.getFuncName() + ": " + e.getDetailMsg();
  if (!g_system_reason.empty()) what = g_system_reason + " (" + what + ")";
  g_system_reason.clear();
  return what;
}

}  // namespace rocklab::sim::output::detail
