// runScene in three parts (run/run_internal.h): set-up, stepping, results.
#include "rocklab/experiments/run.h"

#include <atomic>
#include <utility>
#include <vector>
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

namespace {

/// `release` runs between the set-up and the stepping (a scene the run owns frees its
/// particle lists there).
template <class Release>
int runWith(const Scene& scene, const RunOptions& options, std::ostream& log, Release&& release) {
  detail::RunTimes times{detail::Clock::now(), {}};
  clearStopRequest();
  detail::RunSetup setup;
  setup.started = times.start;
  if (const int rc = detail::setUpRun(scene, options, log, setup); rc != kExitOk) return rc;
  release();
  times.setup_done = detail::Clock::now();
  detail::RunRecord record = detail::stepRun(scene, options, log, setup);
  return detail::writeResults(scene, options, setup, record, times, log);
}

}  // namespace

int runScene(const Scene& scene, const RunOptions& options, std::ostream& log) {
  return runWith(scene, options, log, [] {});
}

int runScene(Scene&& scene, const RunOptions& options, std::ostream& log) {
  // The World copied them and the experiment took what it needs when it was made
  // (setUpRun); nothing after reads them (the peak of a large run is its first
  // neighbour lists, after this).
  return runWith(scene, options, log, [&scene] {
    std::vector<sim::SphereSpec>().swap(scene.spheres);
    std::vector<sim::ClumpSpec>().swap(scene.clumps);
    std::vector<sim::BondSpec>().swap(scene.bonds);
  });
}

}  // namespace rocklab::experiments
