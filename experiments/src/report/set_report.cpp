#include "report/set_report.h"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/json_text.h"
#include "report/html.h"

namespace rocklab::experiments::detail {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr std::size_t kMaxTableRows = 1000;  // a longer table is cut on the page (the CSV is linked)

/// A line of a set's table, each cell as HTML text.
std::vector<std::string> htmlCells(const std::string& line) {
  std::vector<std::string> cells = detail::splitCsvLine(line);
  for (std::string& c : cells) c = htmlText(c);
  return cells;
}

/// The tables a set writes (sweep.csv, study.csv, calibration.csv, ...) as written:
/// one row a line, cells as common/csv.h writes them (run_set.h writeTable).
std::string csvTable(const fs::path& dir, const fs::path& csv) {
  std::ifstream in(dir / csv);
  std::string line;
  if (!std::getline(in, line)) return "";
  const std::vector<std::string> header = htmlCells(line);
  std::vector<std::vector<std::string>> rows;
  std::size_t total = 0;
  while (std::getline(in, line))
    if (++total <= kMaxTableRows) rows.push_back(htmlCells(line));
  std::string s = "<h3>" + link(csv, csv.string()) + "</h3>\n" + htmlTable(header, rows);
  if (total > kMaxTableRows)
    s += "<p>The first " + std::to_string(kMaxTableRows) + " of " + std::to_string(total) + " rows; all in " +
         link(csv, csv.string()) + ".</p>\n";
  return s;
}

/// What the set concluded: the study's recommendation, a calibration's estimate.
std::string conclusions(const fs::path& dir) {
  std::string s;
  for (const char* name : {"study.json", "calibration.json", "weibull.json"}) {
    const json j = readJsonFile(dir / name);
    if (!j.is_object()) continue;
    std::vector<std::vector<std::string>> rows;
    for (const auto& [key, v] : j.items())
      if (v.is_primitive()) rows.push_back({htmlText(key), htmlText(v.is_string() ? v.get<std::string>() : v.dump())});
    s += "<h3>" + link(name, name) + "</h3>\n";
    if (j.contains("recommendation") && j["recommendation"].is_string())
      s += "<p><strong>Recommendation:</strong> " + htmlText(j["recommendation"].get<std::string>()) + "</p>\n";
    s += htmlTable({"key", "value"}, rows);
  }
  return s.empty() ? "" : htmlSection("Conclusion", s);
}

/// The folders of the set's runs (and of the sets inside it: a calibration's trials
/// and batch), relative to `dir`: subfolders of `dir` and of `dir`/runs holding a
/// results.json, a page, or (a run that failed early) a run.log.
std::vector<fs::path> runFolders(const fs::path& dir) {
  std::vector<fs::path> runs;
  for (const fs::path& parent : {fs::path(), fs::path("runs")}) {
    std::error_code ec;
    for (fs::directory_iterator it(dir / parent, ec), end; !ec && it != end; it.increment(ec)) {
      const fs::path& p = it->path();
      if (it->is_directory(ec) && (fs::exists(p / "results.json") || fs::exists(p / "report.html") ||
                                   fs::exists(p / "run.log") || isSetFolder(p)))
        runs.push_back(parent / p.filename());
    }
  }
  std::sort(runs.begin(), runs.end());
  return runs;
}

/// Each run of the set: its page (or its folder when it has none yet) and how it ended.
std::string runLinks(const fs::path& dir) {
  const std::vector<fs::path> runs = runFolders(dir);
  if (runs.empty()) return "";
  std::vector<std::vector<std::string>> rows;
  for (const fs::path& folder : runs) {
    const fs::path run = folder;
    const bool has_page = fs::exists(dir / folder / "report.html");
    const json r = readJsonFile(dir / folder / "results.json");
    const std::string status = r.is_object() && r.contains("status") && r["status"].is_string()
                                   ? r["status"].get<std::string>()
                               : isSetFolder(dir / folder) ? "a set of runs"
                                                           : "no results.json (failed before it wrote one, or not run yet)";
    rows.push_back({has_page ? link(folder / "report.html", run.string()) : link(folder, run.string()),
                    htmlText(status)});
  }
  return htmlSection("Runs", htmlTable({"run (its page)", "status"}, rows));
}

std::string setKind(const fs::path& dir) {
  if (fs::exists(dir / "study.json")) return "study";
  if (fs::exists(dir / "calibration.csv") || fs::exists(dir / "calibration.json")) return "calibration";
  return "sweep";
}

}  // namespace

bool isSetFolder(const fs::path& dir) {
  std::error_code ec;
  return fs::exists(dir / "plan.json", ec) || fs::exists(dir / "calibration.csv", ec) ||
         fs::is_directory(dir / "runs", ec);
}

std::string setReportHtml(const fs::path& dir) {
  fs::path folder = fs::absolute(dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();  // "out/sweep/" ends in a separator
  const std::string title = "rocklab " + setKind(dir) + ": " + folder.filename().string();
  std::string tables, figures;
  for (const fs::path& csv : filesWithExtension(dir, ".csv"))
    if (csv.stem().extension() != ".plot") tables += csvTable(dir, csv);  // a plot's data is linked under it
  for (const fs::path& png : filesWithExtension(dir, ".png")) figures += htmlFigure(dir, png, png.stem().string());
  std::string body = "<h1>" + htmlText(title) + "</h1>\n" + conclusions(dir);
  if (!tables.empty()) body += htmlSection("Tables", tables);
  if (!figures.empty()) body += htmlSection("Plots", figures);
  body += runLinks(dir) + htmlSection("Files", htmlFileList(dir));
  return htmlPage(title, body);
}

void writeSetReport(const fs::path& dir) {
  writeAtomically(dir / "report.html", setReportHtml(dir));
}

void refreshSetReport(const fs::path& dir, std::ostream& log, const std::string& who) {
  try {
    writeSetReport(dir);
  } catch (const std::exception& e) {
    log << who << ": no report.html (" << e.what() << ")\n";
  }
}

}  // namespace rocklab::experiments::detail
