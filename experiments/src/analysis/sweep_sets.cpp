#include "analysis/sweep_sets.h"

#include <algorithm>
#include <set>

#include "common/joined_text.h"
#include "sets/plan_file.h"

namespace rocklab::experiments::detail {

SweepSet readSweepSet(const std::filesystem::path& dir) {
  SweepSet set;
  set.dir = dir;
  PlanFile plan;
  try {
    plan = readPlanFile(dir);
  } catch (const PlanFileError& e) {
    throw SweepSetError(e.what());
  }
  if (plan.kind != "sweep")
    throw SweepSetError((dir / "plan.json").string() + ": kind \"" + plan.kind +
                        "\" (allowed: \"sweep\"; a study merges its seeds itself, `rocklab study --seeds`)");
  for (const auto& [key, values] : plan.options.vary) set.keys.push_back(key);
  set.x_over = plan.options.x_over;
  try {
    set.table = readCsvTable(dir / "sweep.csv", " (a finished sweep's folder holds it; `rocklab collect " +
                                                    dir.string() + "` writes it from the runs)");
    for (const std::string& key : set.keys) set.table.column(key);
  } catch (const std::invalid_argument& e) {
    throw SweepSetError(e.what());
  }
  return set;
}

std::vector<std::string> figureColumns(const SweepSet& s) {
  std::vector<std::string> figures;
  for (const std::string& h : s.table.header)
    if (h != "status" && std::find(s.keys.begin(), s.keys.end(), h) == s.keys.end()) figures.push_back(h);
  return figures;
}

std::string sortedNames(std::vector<std::string> names) {
  std::sort(names.begin(), names.end());
  return names.empty() ? "none" : joinedText(names);
}

void checkSameShape(const std::vector<SweepSet>& sets, const std::string& what_allowed) {
  const SweepSet& first = sets.front();
  const std::set<std::string> keys(first.keys.begin(), first.keys.end());
  const std::vector<std::string> first_figures = figureColumns(first);
  const std::set<std::string> figures(first_figures.begin(), first_figures.end());
  for (const SweepSet& s : sets) {
    if (std::set<std::string>(s.keys.begin(), s.keys.end()) != keys)
      throw SweepSetError((s.dir / "plan.json").string() + ": varies " + sortedNames(s.keys) + ", " +
                          (first.dir / "plan.json").string() + " varies " + sortedNames(first.keys) +
                          " (allowed: sweeps of the same keys, " + what_allowed + ")");
    const std::vector<std::string> own = figureColumns(s);
    if (std::set<std::string>(own.begin(), own.end()) != figures)
      throw SweepSetError(s.table.file.string() + ": figures " + sortedNames(own) + ", " + first.table.file.string() +
                          " has " + sortedNames(first_figures) + " (allowed: sweeps with the same --metric figures)");
    if (s.x_over != first.x_over || (!s.x_over.empty() && s.keys.front() != first.keys.front()))
      throw SweepSetError((s.dir / "plan.json").string() + ": --x-over \"" + s.x_over + "\" of " + s.keys.front() +
                          ", " + (first.dir / "plan.json").string() + " \"" + first.x_over + "\" of " +
                          first.keys.front() + " (allowed: sweeps plotted against the same x)");
  }
}

}  // namespace rocklab::experiments::detail
