// rocklab executable: all logic lives in rocklab_experiments (testable in-process).
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>

#include "rocklab/experiments/cli.h"
#include "rocklab/experiments/run.h"

namespace {

/// How long a waiting OpenMP thread spins before it sleeps, unless the user sets it
/// (see below): 1000 turns, a few microseconds.
constexpr const char* kSpinCount = "1000";

/// runCli catches every exception of a command; this is for what escapes even that
/// (a throw from a destructor or a noexcept function): one line and exit code 1
/// ("failed") instead of abort()'s core dump and 134.
[[noreturn]] void onTerminate() {
  std::fputs("error: rocklab: stopped by an internal error (std::terminate); please report it\n", stderr);
  std::_Exit(rocklab::experiments::kExitFailed);
}

/// OpenMP threads that wait at a barrier spin by default (libgomp: ~300,000 turns) before
/// they sleep. On a core that another process holds, the spinning thread takes the time
/// the working one needs: a 16,000-ball settle of 2,000 steps took 18.6-29.7 s on two
/// threads beside a busy process, against 2.9-3.7 s on one. Sleeping at once (passive)
/// costs 29 % on an idle machine; 1000 turns cost nothing measurable idle and keep two
/// threads as fast as one under load (docs/performance.md). libgomp reads the setting
/// once when it is loaded, before main, so when the user has set neither
/// OMP_WAIT_POLICY nor GOMP_SPINCOUNT the process sets it and starts itself again (same
/// pid, arguments and files); a user's own setting is kept as it is.
void chooseOpenMpWaitPolicy(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("GOMP_SPINCOUNT")) return;
  if (::setenv("GOMP_SPINCOUNT", kSpinCount, 1) != 0) return;
  ::execv("/proc/self/exe", argv);  // returns only if it failed: go on with the default
}

}  // namespace

int main(int argc, char** argv) {
  chooseOpenMpWaitPolicy(argv);
  std::set_terminate(onTerminate);
  return rocklab::experiments::runCli(argc, argv);
}
