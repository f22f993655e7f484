#pragma once
// report.html of a sweep, study or calibration folder: its tables (every CSV of
// the folder), plots, recommendation or estimate, and a link to each run's page.
// Made from the folder's files only, like the run page. Internal.
#include <filesystem>
#include <iosfwd>
#include <string>

namespace rocklab::experiments::detail {

/// A folder a sweep, study or calibration wrote: plan.json, calibration.csv or runs/.
bool isSetFolder(const std::filesystem::path& dir);

/// The page of the set in `dir`.
std::string setReportHtml(const std::filesystem::path& dir);

/// Writes dir/report.html atomically; throws sim::output::OutputError when it cannot.
void writeSetReport(const std::filesystem::path& dir);

/// writeSetReport at the end of a sweep, study, calibration or Weibull fit: a page
/// that cannot be written is said in `log` ("<who>: no report.html (why)"), like a
/// plot that cannot be drawn; the set's table and figures stand without it.
void refreshSetReport(const std::filesystem::path& dir, std::ostream& log, const std::string& who);

}  // namespace rocklab::experiments::detail
