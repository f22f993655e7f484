// runScene in three parts (run/run_internal.h): set-up, stepping, results.
#include "rocklab/experiments/run.h"

#include <atomic>
#include <ostream>

#include "run/run_internal.h"

namespace rocklab::experiments {

namespace {
std::atomic<bool> g_stop{false};
}  // namespace

void requestStop() {
  g_stop = true;
}
bool stopRequested() {
  return g_stop;
}
void clearStopRequest() {
  g_stop = false;
}

int runScene(const Scene& scene, const RunOptions& options, std::ostream& log) {
  detail::RunTimes times{detail::Clock::now(), {}};
  clearStopRequest();
  detail::RunSetup setup;
  if (const int rc = detail::setUpRun(scene, options, log, setup); rc != kExitOk) return rc;
  times.setup_done = detail::Clock::now();
  detail::RunRecord record = detail::stepRun(scene, options, log, setup);
  return detail::writeResults(scene, options, setup, record, times, log);
}

}  // namespace rocklab::experiments
