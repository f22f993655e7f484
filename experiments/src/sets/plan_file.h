#pragma once
// plan.json read back for `rocklab collect`: every key the collect step uses is
// checked (type, non-empty lists, one value per varied key, plain run folder
// names) before anything indexes it, so a damaged or hand-edited plan gives one
// message naming the file and the key, never a crash.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sets/run_plan.h"

namespace rocklab::experiments::detail {

struct PlanFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct PlanFile {
  std::string kind;                 // "sweep" | "study"
  SweepOptions options;             // scene, overrides, vary
  std::vector<std::string> metrics;  // sweep: the figures of its table (non-empty)
  std::vector<PlannedRun> runs;     // non-empty
  nlohmann::json raw;               // the whole file (a study's own settings, checked here too)
};

/// Reads and checks DIR/plan.json; throws PlanFileError naming the file and key.
PlanFile readPlanFile(const std::filesystem::path& dir);

/// results.json's "status" when it is a string, else "" (a damaged file is no run).
std::string resultStatus(const nlohmann::json& results);

/// True when the run folder `dir` holds the results.json of a completed run.
bool runCompleted(const std::filesystem::path& dir);

}  // namespace rocklab::experiments::detail
