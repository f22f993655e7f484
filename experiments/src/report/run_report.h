#pragma once
// report.html of one run: what was run, its headline figures with units (beside
// the reference value the run itself reports: the analytic restitution, the DEM
// truth of the tracked markers), plots, movie and stills, time-step audit,
// stability checks, wall time by stage, and every file of the folder linked.
// Made from results.json and the folder's files only, so `rocklab report DIR`
// rebuilds the same page a run wrote. Internal to rocklab_experiments.
#include <filesystem>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>

namespace rocklab::experiments::detail {

/// The page of the run whose results are `results` (its results.json) in `dir`.
std::string runReportHtml(const std::filesystem::path& dir, const nlohmann::json& results);

/// Writes dir/report.html atomically; throws sim::output::OutputError when it cannot.
void writeRunReport(const std::filesystem::path& dir, const nlohmann::json& results);

/// `rocklab report DIR`: rebuilds the page of a run folder (results.json) or of a
/// sweep, study or calibration folder. Exit 2 naming the folder and what is
/// missing when it is neither, or when its results.json cannot be read.
int reportCommand(const std::filesystem::path& dir, std::ostream& log);

}  // namespace rocklab::experiments::detail
