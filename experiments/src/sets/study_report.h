#pragma once
// The study's report from a plan folder, for `rocklab collect`. Internal.
#include <filesystem>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <vector>

#include "sets/run_plan.h"

namespace rocklab::experiments::detail {

/// Table, plot and recommendation of a study set from plan.json and what its runs
/// left (inspectRuns).
int collectStudy(const std::filesystem::path& dir, const SweepOptions& runs_options, const nlohmann::json& plan,
                 const std::vector<PlannedRun>& runs, const std::vector<Variant>& done, std::ostream& log);

}  // namespace rocklab::experiments::detail
