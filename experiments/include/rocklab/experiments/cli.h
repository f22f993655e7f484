#pragma once
// The rocklab command line (CLI11). Kept in the library so tests can run it in-process.
namespace rocklab::experiments {
/// Parses and runs a command; returns the process exit code (see run.h).
int runCli(int argc, const char* const* argv);
}  // namespace rocklab::experiments
