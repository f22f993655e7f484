#pragma once
// Running a scene: builds the world, steps it with progress on stderr, writes
// run.h5 / .vtp series / checkpoint.h5 / results.json / report.html into the output directory.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "rocklab/experiments/scene.h"

namespace rocklab::experiments {

/// Exit codes of the CLI.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailed = 1,       // the run stopped on an error that is not the input's (message in results.json)
  kExitBadInput = 2,     // scene, option or file the user gave is unusable; nothing written
  kExitWatchdog = 3,     // the stability watchdog stopped the run; outputs so far kept
  kExitRunsFailed = 4,   // a multi-run command finished, but some of its runs failed (see its table)
  kExitInterrupted = 130,  // Ctrl-C, SIGTERM or SIGHUP; outputs so far kept and readable
};

/// What a run does with an earlier run in its output folder (a folder holding
/// results.json, run.h5, checkpoint.h5 or vtk/, finished or not).
enum class EarlierRun {
  Keep,     // write over it file by file (callers that make fresh folders themselves)
  Refuse,   // exit 2, nothing touched (`rocklab run` without --overwrite)
  Replace,  // remove its outputs first (results.json, report.html, run.h5, checkpoint.h5, vtk/, frames/ and
            // every .png .svg .mp4 .avi .csv .json .partial .tmp), so no file of it sits beside the new run's
};

struct RunOptions {
  std::filesystem::path out_dir = "out";
  int threads = 0;           // 0 = all cores
  bool progress = true;      // progress line on stderr for runs over a few seconds
  std::filesystem::path restart;  // checkpoint to continue from ("" = start at t = 0)
  EarlierRun earlier_run = EarlierRun::Keep;
};

/// Runs a loaded scene. Returns an ExitCode; writes messages to `log`.
int runScene(const Scene& scene, const RunOptions& options, std::ostream& log);
/// The same for a scene the run may take apart: once the World (and the experiment)
/// hold the particles, the scene's own lists of spheres, clumps and bonds are freed
/// (about 90 bytes a sphere for the rest of the run; the caller gets them back empty).
int runScene(Scene&& scene, const RunOptions& options, std::ostream& log);

/// Requests a clean stop of the running scene (called from the SIGINT, SIGTERM and SIGHUP handler).
void requestStop();
/// True after requestStop() until the next run starts.
bool stopRequested();
/// Forgets a stop request (what starting a run does).
void clearStopRequest();

}  // namespace rocklab::experiments
