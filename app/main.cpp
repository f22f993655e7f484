// rocklab executable: all logic lives in rocklab_experiments (testable in-process).
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "rocklab/experiments/cli.h"
#include "rocklab/experiments/run.h"

namespace {

/// runCli catches every exception of a command; this is for what escapes even that
/// (a throw from a destructor or a noexcept function): one line and exit code 1
/// ("failed") instead of abort()'s core dump and 134.
[[noreturn]] void onTerminate() {
  std::fputs("error: rocklab: stopped by an internal error (std::terminate); please report it\n", stderr);
  std::_Exit(rocklab::experiments::kExitFailed);
}

}  // namespace

int main(int argc, char** argv) {
  std::set_terminate(onTerminate);
  return rocklab::experiments::runCli(argc, argv);
}
