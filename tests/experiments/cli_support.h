#pragma once
// Runs the CLI in-process, as `rocklab ARGS...` would: returns the exit code.
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

}  // namespace rocklab::experiments::test
