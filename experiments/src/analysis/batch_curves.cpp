#include "analysis/batch_curves.h"

#include <algorithm>
#include <map>
#include <ostream>
#include <stdexcept>

#include "analysis/plot.h"
#include "analysis/sweep_table.h"
#include "sets/plan_file.h"

namespace rocklab::experiments {

namespace fs = std::filesystem;

namespace {

/// At most this many points of a curve are drawn (every k-th row, the last kept):
/// a crush logs thousands of rows, and 60 curves of them make a slow, heavy SVG.
constexpr std::size_t kMaxPointsPerCurve = 600;

/// travel (mm) and top force (kN) of one run's force_displacement.csv; throws
/// std::invalid_argument naming the file when a column is missing.
PlotSeries curveOf(const fs::path& csv) {
  const SweepTable t = readCsvTable(csv);
  const std::size_t travel = t.column("travel_m"), force = t.column("top_force_N");
  PlotSeries s{"", {}, {}, PlotSeries::Style::Line};
  const std::size_t every = std::max<std::size_t>(1, (t.rows.size() + kMaxPointsPerCurve - 1) / kMaxPointsPerCurve);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    if (i % every != 0 && i + 1 != t.rows.size()) continue;
    const auto x = SweepTable::numberIn(t.rows[i], travel), y = SweepTable::numberIn(t.rows[i], force);
    if (!x || !y) continue;
    s.x.push_back(*x * 1e3);
    s.y.push_back(*y * 1e-3);
  }
  return s;
}

}  // namespace

std::size_t writeBatchForceCurves(const fs::path& dir, const std::string& group_by, std::ostream& log) {
  if (!fs::exists(dir / "plan.json")) return 0;
  detail::PlanFile plan;
  try {
    plan = detail::readPlanFile(dir);
  } catch (const detail::PlanFileError& e) {
    log << "force-displacement curves: skipped (" << e.what() << ")\n";
    return 0;
  }
  std::size_t group_key = plan.options.vary.size();
  for (std::size_t k = 0; k < plan.options.vary.size(); ++k)
    if (plan.options.vary[k].first == group_by) group_key = k;
  // Groups in the order of their first run (the plan's order: the values as varied).
  std::vector<std::string> groups;
  std::map<std::string, std::size_t> runs_in;
  std::vector<PlotSeries> curves;
  for (const detail::PlannedRun& run : plan.runs) {
    const fs::path run_dir = dir / "runs" / run.name, csv = run_dir / "force_displacement.csv";
    if (!detail::runCompleted(run_dir) || !fs::exists(csv)) continue;
    PlotSeries curve;
    try {
      curve = curveOf(csv);
    } catch (const std::invalid_argument& e) {
      log << "force-displacement curves: skipped " << e.what() << "\n";
      continue;
    }
    if (curve.x.empty()) continue;
    curve.data_name = run.name;
    const std::string group = group_key < run.values.size() ? run.values[group_key] : "";
    auto at = std::find(groups.begin(), groups.end(), group);
    if (at == groups.end()) at = groups.insert(groups.end(), group);
    curve.colour = static_cast<int>(at - groups.begin());
    ++runs_in[group];
    curves.push_back(std::move(curve));
  }
  if (curves.empty()) return 0;
  // One legend entry per group: on its first curve.
  std::vector<bool> labelled(groups.size(), false);
  for (PlotSeries& c : curves) {
    const auto g = static_cast<std::size_t>(c.colour);
    if (labelled[g]) continue;
    labelled[g] = true;
    const std::string runs = std::to_string(runs_in[groups[g]]) + (runs_in[groups[g]] == 1 ? " run" : " runs");
    c.label = groups[g].empty() ? runs : group_by + " = " + groups[g] + ": " + runs;
  }
  PlotSpec spec;
  spec.title = "Force against platen travel, " + std::to_string(curves.size()) + " crushing tests";
  spec.x_label = "top platen travel (mm)";
  spec.y_label = "top platen force (kN)";
  spec.series = std::move(curves);
  const std::size_t drawn = spec.series.size();
  try {
    writePlot(spec, dir / "force_displacement.png");
  } catch (const std::exception& e) {
    log << "force-displacement curves: no plot (" << e.what() << ")\n";
    return 0;
  }
  log << "force-displacement curves: " << drawn << " runs in " << (dir / "force_displacement.png").string() << "\n";
  return drawn;
}

}  // namespace rocklab::experiments
