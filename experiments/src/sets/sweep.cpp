#include "rocklab/experiments/sweep.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/json_text.h"
#include "analysis/plot.h"
#include "sets/plan_file.h"
#include "sets/run_plan.h"
#include "sets/run_set.h"
#include "sets/study_report.h"
#include "report/set_report.h"
#include "scene/scene_keys.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"

namespace rocklab::experiments {

namespace {

using json = nlohmann::json;
using namespace detail;

/// The figures a sweep reports when none are named: the experiment's headline.
std::vector<std::string> defaultMetrics(const Scene& scene) {
  const std::string& type = scene.experiment_type;
  std::vector<std::string> m;
  if (type == "drop") m = {"restitution", "drop.contact_time_s"};
  if (type == "heap") m = {"angle_of_repose_deg", "heap.settled"};
  if (type == "chute") m = {"clearance_time_s", "jammed", "chute.bodies"};
  if (type == "zwick")
    m = {"strength_MPa", "peak_force_N", "zwick.platen_gap_at_peak_m", "zwick.load_imbalance_loading",
         "bonds_broken", "sphere_count", "bond_count", "porosity", "coordination_number"};
  if (type == "crusher")  // the §g.9 studies' figures; the product curves are plotted beside (below)
    m = {"crusher.p50_mm", "crusher.p80_mm", "crusher.throughput_tph", "crusher.power_W", "crusher.breakages",
         "crusher.empty", "crusher.discharged_mass_kg", "crusher.in_chamber_mass_kg"};
  m.push_back("simulated_time_s");
  m.push_back("wall_time_s.total");
  return m;
}

/// The sweep's table: the varied values, the chosen figures, how each run ended.
void writeMetricTable(const SweepOptions& o, const std::vector<std::string>& metrics, const std::vector<Variant>& points,
                      const std::filesystem::path& csv_path, std::ostream& log) {
  std::vector<std::string> header;
  for (const auto& [key, values] : o.vary) header.push_back(key);
  for (const auto& m : metrics) header.push_back(m);
  header.push_back("status");
  std::vector<std::vector<std::string>> rows;
  for (const Variant& p : points) {
    std::vector<std::string> row = p.values;
    for (const auto& m : metrics) row.push_back(cell(lookup(p.results, m)));
    row.push_back(!p.status.empty() ? p.status : p.code == kExitOk ? "ok" : "exit " + std::to_string(p.code));
    rows.push_back(row);
  }
  writeTable(header, rows, csv_path, log);
}

}  // namespace

std::pair<std::string, std::vector<std::string>> parseVary(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == assignment.size())
    throw std::invalid_argument("--vary '" + assignment + "': expected key=a,b,c (or key=lo:hi for calibrate)");
  // Commas inside brackets belong to a value: key=[0,0,0.03],[0,0,0.05].
  std::vector<std::string> values;
  std::string v;
  int depth = 0;
  for (const char ch : assignment.substr(eq + 1)) {
    depth += (ch == '[') - (ch == ']');
    if (ch == ',' && depth == 0) {
      if (!v.empty()) values.push_back(v);
      v.clear();
    } else {
      v += ch;
    }
  }
  if (!v.empty()) values.push_back(v);
  if (values.empty()) throw std::invalid_argument("--vary '" + assignment + "': no values");
  return {assignment.substr(0, eq), values};
}

namespace {

/// Crusher sweeps (the reference's studies, experiments.md §g.9, report a product
/// curve per case): every run's cumulative passing on one sieve chart,
/// product_curves.png, labelled by its varied values, with the first run's feed.
/// A run whose chamber was not empty at its end is labelled so: its curve is the
/// product discharged so far. Nothing is drawn when no run has a product curve.
void writeProductCurves(const std::filesystem::path& dir, const SweepOptions& o, const std::vector<Variant>& done,
                        const std::string& name, std::ostream& log) {
  PlotSpec spec = sieveChart(name + ": product size distribution of each run");
  // A row that is not {size_mm, passing} (a damaged results.json) is a gap in the line.
  auto curve = [](const json& psd, PlotSeries& s) {
    for (const json& row : psd) {
      const bool ok = row.is_object();
      s.x.push_back(ok ? number(row.value("size_mm", json())) : std::numeric_limits<double>::quiet_NaN());
      s.y.push_back(ok ? 100 * number(row.value("passing", json())) : std::numeric_limits<double>::quiet_NaN());
    }
  };
  for (const Variant& p : done) {
    const json psd = lookup(p.results, "crusher.psd");
    if (!psd.is_array() || psd.empty()) continue;
    if (spec.series.empty())
      if (const json feed = lookup(p.results, "crusher.feed_psd"); feed.is_array() && !feed.empty()) {
        PlotSeries f{"feed", {}, {}, PlotSeries::Style::Line};
        curve(feed, f);
        spec.series.push_back(f);
      }
    PlotSeries s;
    for (std::size_t k = 0; k < o.vary.size(); ++k)
      s.label += (k > 0 ? ", " : "") + o.vary[k].first + " = " + p.values[k];
    if (lookup(p.results, "crusher.empty") != json(true)) s.label += " (chamber not empty)";
    curve(psd, s);
    spec.series.push_back(s);
  }
  if (spec.series.size() < 2) return;  // no product curve (at most the feed)
  try {
    writePlot(spec, dir / "product_curves.png");
    log << "sweep: product curves " << (dir / "product_curves.png").string() << "\n";
  } catch (const std::exception& e) {
    log << "sweep: no product curves (" << e.what() << ")\n";
  }
}

/// The sweep's table and plot from what its runs left (inspectRuns: in-process,
/// processes or collect).
int reportSweep(const std::filesystem::path& dir, const SweepOptions& o, const std::vector<std::string>& metrics,
                const std::vector<Variant>& done, const std::string& name, std::ostream& log) {
  writeMetricTable(o, metrics, done, dir / "sweep.csv", log);
  writeProductCurves(dir, o, done, name, log);
  // Plot: the first metric against the first key (or its value over o.x_over);
  // one series per value of the second key.
  PlotSpec spec;
  const std::string x_name = o.x_over.empty() ? o.vary.front().first : o.vary.front().first + " / " + o.x_over;
  spec.title = name + ": " + metrics.front() + " against " + x_name;
  spec.x_label = o.x_over.empty() ? withSceneKeyUnit(x_name) : x_name;
  spec.y_label = metrics.front();
  const std::size_t groups = o.vary.size() > 1 ? o.vary[1].second.size() : 1;
  for (std::size_t g = 0; g < groups; ++g) {
    PlotSeries s;
    if (o.vary.size() > 1) s.label = o.vary[1].first + " = " + o.vary[1].second[g];
    for (const Variant& p : done) {
      if (o.vary.size() > 1 && p.values[1] != o.vary[1].second[g]) continue;
      try {
        s.x.push_back(toDouble(p.values[0], o.vary.front().first));
      } catch (const std::invalid_argument&) {
        s.x.push_back(static_cast<double>(s.x.size()));  // a non-numeric key is plotted by position
      }
      if (!o.x_over.empty()) s.x.back() /= number(lookup(p.results, o.x_over));  // a failed run: NaN, no point
      s.y.push_back(number(lookup(p.results, metrics.front())));
    }
    spec.series.push_back(s);
  }
  try {
    writePlot(spec, dir / "sweep.png");
  } catch (const std::exception& e) {
    log << "sweep: no plot (" << e.what() << ")\n";
  }
  refreshSetReport(dir, log, "sweep");
  log << "sweep: table " << (dir / "sweep.csv").string() << ", plot " << (dir / "sweep.png").string() << ", page "
      << (dir / "report.html").string() << "\n";
  return allOk(done) ? kExitOk : kExitRunsFailed;
}

}  // namespace

int runSweep(const SweepOptions& o, std::ostream& log) {
  if (o.vary.empty()) {
    log << "error: sweep: give at least one --vary key=a,b,c\n";
    return kExitBadInput;
  }
  // Every combination, the first key slowest, validated before anything runs: an
  // invalid variant is listed as failed (exit 2) and costs nothing; when none is
  // valid, nothing is written.
  const std::vector<PlannedRun> runs = planRuns(o);
  const auto valid = std::find_if(runs.begin(), runs.end(), [](const PlannedRun& r) { return r.invalid.empty(); });
  if (valid == runs.end()) {
    log << "error: " << runs.front().invalid << "\n";
    return kExitBadInput;
  }
  if (!o.x_over.empty())
    for (const std::string& v : o.vary.front().second) try {
        toDouble(v, "--vary " + o.vary.front().first);
      } catch (const std::invalid_argument& e) {
        log << "error: sweep: --x-over " << o.x_over << " divides the first --vary key's values, which must be numbers: "
            << e.what() << "\n";
        return kExitBadInput;
      }
  const Scene first = sceneFor(o, valid->values);
  std::vector<std::string> metrics = o.metrics.empty() ? defaultMetrics(first) : o.metrics;
  if (!o.x_over.empty() && std::find(metrics.begin(), metrics.end(), o.x_over) == metrics.end())
    metrics.push_back(o.x_over);  // the divisor in the table beside the figures
  const std::filesystem::path dir = outDirFor(o, first, "-sweep");
  json plan_extra{{"kind", "sweep"}, {"metrics", metrics}};
  if (!o.x_over.empty()) plan_extra["x_over"] = o.x_over;
  writePlanFiles(dir, o, runs, plan_extra);
  log << "sweep of " << first.run.name << ": " << runs.size() << " runs into " << dir.string() << "\n";
  if (o.plan_only) return reportPlan(dir, runs, "sweep", log);
  const int code = executeRuns(dir, o, runs, log);
  const int report = reportSweep(dir, o, metrics, inspectRuns(dir, runs), first.run.name, log);
  return code != kExitOk ? code : report;
}

int collectSet(const std::filesystem::path& dir, std::ostream& log) {
  PlanFile plan;
  try {
    plan = readPlanFile(dir);
  } catch (const PlanFileError& e) {
    log << "error: collect: " << e.what() << "\n";
    return kExitBadInput;
  }
  const SweepOptions& o = plan.options;
  const std::vector<Variant> done = inspectRuns(dir, plan.runs);
  std::size_t complete = 0, failed = 0, missing = 0;
  for (const Variant& v : done) (v.code == kExitOk ? complete : v.code == kMissing ? missing : failed) += 1;
  const std::string name = sourceName(o.scene);
  log << "collect " << plan.kind << " of " << name << ": " << complete << " complete, " << failed << " failed, "
      << missing << " missing of " << plan.runs.size() << " runs\n";
  if (plan.kind == "sweep") return reportSweep(dir, o, plan.metrics, done, name, log);
  return collectStudy(dir, o, plan.raw, plan.runs, done, log);
}

int runCalibrate(const CalibrateOptions& c, std::ostream& log) {
  const SweepOptions& o = c.sweep;
  if (o.vary.size() != 1) {
    log << "error: calibrate: give exactly one --vary key=a,b,c or key=lo:hi\n";
    return kExitBadInput;
  }
  const std::string& key = o.vary.front().first;
  const auto& given = o.vary.front().second;
  const bool range = given.size() == 1 && given.front().find(':') != std::string::npos;
  std::vector<double> values;
  try {
    if (range) {
      const std::string& r = given.front();
      values = {toDouble(r.substr(0, r.find(':')), "--vary " + key), toDouble(r.substr(r.find(':') + 1), "--vary " + key)};
    } else {
      for (const auto& v : given) values.push_back(toDouble(v, "--vary " + key));
    }
  } catch (const std::invalid_argument& e) {
    log << "error: calibrate: " << e.what() << "\n";
    return kExitBadInput;
  }
  Scene first;
  try {
    for (double v : values) first = sceneFor(o, {cell(v)});
  } catch (const SceneError& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  const std::filesystem::path dir = outDirFor(o, first, "-calibrate");
  std::filesystem::create_directories(dir);
  log << "calibrate " << first.run.name << ": " << key << " for " << c.target_metric << " = " << c.target << "\n";
  std::vector<Variant> tried;
  auto evaluate = [&](double v) -> double {
    Variant p;
    p.values = {cell(v)};
    runVariant(o, dir / variantFolder(tried.size()), p, log);
    tried.push_back(p);
    if (p.code == kExitInterrupted) throw std::runtime_error("interrupted");
    return number(lookup(p.results, c.target_metric)) - c.target;
  };
  std::vector<std::string> metrics{c.target_metric, "wall_time_s.total"};
  double estimate = std::numeric_limits<double>::quiet_NaN();
  std::string how;
  try {
    if (range) {
      double lo = values[0], hi = values[1];
      double f_lo = evaluate(lo), f_hi = evaluate(hi);
      if (!(f_lo * f_hi <= 0)) {
        how = "the target is not between the values at " + cell(lo) + " and " + cell(hi);
      } else {
        for (int k = 0; k < c.iterations; ++k) {
          const double mid = 0.5 * (lo + hi);
          const double f_mid = evaluate(mid);
          if (!std::isfinite(f_mid)) break;
          if ((f_mid <= 0) == (f_lo <= 0)) {
            lo = mid;
            f_lo = f_mid;
          } else {
            hi = mid;
            f_hi = f_mid;
          }
        }
        estimate = f_hi == f_lo ? lo : lo - f_lo * (hi - lo) / (f_hi - f_lo);
        how = "bisection, then linear interpolation in the last bracket [" + cell(lo) + ", " + cell(hi) + "]";
      }
    } else {
      std::vector<double> f;
      for (double v : values) f.push_back(evaluate(v));
      for (std::size_t k = 0; k + 1 < values.size(); ++k)
        if (std::isfinite(f[k]) && std::isfinite(f[k + 1]) && f[k] * f[k + 1] <= 0) {
          estimate = f[k + 1] == f[k] ? values[k] : values[k] - f[k] * (values[k + 1] - values[k]) / (f[k + 1] - f[k]);
          how = "linear interpolation between " + cell(values[k]) + " and " + cell(values[k + 1]);
          break;
        }
      if (!std::isfinite(estimate)) how = "the target is not between any two neighbouring values";
    }
  } catch (const std::runtime_error&) {
    writeMetricTable(o, metrics, tried, dir / "calibration.csv", log);
    refreshSetReport(dir, log, "calibrate");
    return kExitInterrupted;
  }
  writeMetricTable(o, metrics, tried, dir / "calibration.csv", log);
  json out = {{"scene", first.run.name}, {"key", key},           {"target_metric", c.target_metric},
              {"target", c.target},      {"method", how},        {"runs", tried.size()},
              {"estimate", detail::finiteOrNull(estimate)},
              {"status", std::isfinite(estimate) ? "done" : "no_estimate"}};
  detail::writeAtomically(dir / "calibration.json", detail::jsonText(out));
  refreshSetReport(dir, log, "calibrate");
  if (!std::isfinite(estimate)) {  // the target was asked for and not found: not a success
    log << "error: calibrate: no estimate: " << how << "; widen the values\n";
    return kExitFailed;
  }
  log << "calibrate: " << key << " = " << cell(estimate) << " gives " << c.target_metric << " = " << c.target << " ("
      << how << ")\n  check it: rocklab " << (restartsFrom(o.scene) ? "restart " : "run ") << detail::shellQuote(o.scene);
  // The overrides every run had, then the estimate: the check runs the same scene.
  for (const std::string& a : o.overrides) log << " --set " << detail::shellQuote(a);
  log << " --set " << key << "=" << cell(estimate) << "\n";
  return kExitOk;
}

}  // namespace rocklab::experiments
