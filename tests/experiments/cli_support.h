#pragma once
// Runs the CLI in-process, as `rocklab ARGS...` would: returns the exit code.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "rocklab/experiments/cli.h"

namespace rocklab::experiments::test {

inline int cli(std::vector<std::string> args) {
  args.insert(args.begin(), "rocklab");
  std::vector<const char*> argv;
  for (auto& a : args) argv.push_back(a.c_str());
  return runCli(static_cast<int>(argv.size()), argv.data());
}

/// The same with what it writes to stderr captured in `log`.
inline int cliLogged(const std::vector<std::string>& args, std::string& log) {
  std::ostringstream captured;
  auto* const old = std::cerr.rdbuf(captured.rdbuf());
  const int code = cli(args);
  std::cerr.rdbuf(old);
  log = captured.str();
  return code;
}

/// An empty scratch path "rocklab-<name>-<pid>" in the temporary folder (the pid
/// keeps two checkouts' suites apart); not created.
inline std::filesystem::path scratchDir(const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / ("rocklab-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  return d;
}

/// Waits (up to a minute) until the run writing into `out` has opened its
/// run.h5.partial, which it does after its stop handlers are in place: a signal
/// sent then stops the run, where one sent while it still loads its scene would
/// meet the default action (a fixed delay lost that race on a loaded machine).
inline void waitUntilRunning(const std::filesystem::path& out) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!std::filesystem::exists(out / "run.h5.partial") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // its first steps (frame 0) done
}

/// A whole file's bytes ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace rocklab::experiments::test
