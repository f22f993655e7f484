#pragma once
// Runs the CLI in-process, as `rocklab ARGS...` would: returns the exit code.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <iostream>
#include <sstream>
#include <string>
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

/// A whole file's bytes ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace rocklab::experiments::test
