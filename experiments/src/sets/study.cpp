#include "rocklab/experiments/study.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <toml++/toml.h>

#include "common/atomic_file.h"
#include "common/json_text.h"
#include "analysis/plot.h"
#include "analysis/sample_statistics.h"
#include "sets/run_plan.h"
#include "sets/run_set.h"
#include "sets/study_report.h"
#include "report/set_report.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "scene/toml_reader.h"

#ifndef ROCKLAB_ASSET_DIR
#define ROCKLAB_ASSET_DIR "assets"
#endif

namespace rocklab::experiments {

using json = nlohmann::json;
using namespace detail;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string joinValues(const SweepOptions& o, const std::vector<std::string>& values) {
  std::string s;
  for (std::size_t k = 0; k < values.size(); ++k) s += (k ? ", " : "") + o.vary[k].first + " = " + values[k];
  return s;
}

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

/// The sentence a user reads: which variant to take and what it costs.
std::string recommendation(const StudyOptions& o, const StudyAnalysis& a, const std::string& reference_text) {
  std::ostringstream s;
  if (!std::isfinite(a.reference)) return "no run completed with the figure: nothing to compare";
  if (!a.recommended) {
    s << "no variant is within " << o.tolerance_pct << (a.reference != 0.0 ? " % of " : " of ") << reference_text
      << " together with all finer ones; refine further";
    return s.str();
  }
  const StudyPoint& best = a.points[*a.recommended];
  s << joinValues(o.runs, best.values);
  if (best.is_reference) {
    s << " (the finest): no cheaper variant is within " << o.tolerance_pct << " % of it together with all finer ones";
    return s.str();
  }
  s << ": " << o.figure << " " << fixed(best.figure, 6);
  if (std::isfinite(best.error_pct))
    s << " is " << fixed(best.error_pct, 3) << " % from " << reference_text << ", and so is every finer variant (tolerance "
      << o.tolerance_pct << " %)";
  else  // a reference of 0: the figure is an error itself, compared in its own unit
    s << " is within " << o.tolerance_pct << " of " << reference_text << ", and so is every finer variant";
  s << ", for " << fixed(best.wall_s, 3) << " s of wall time";
  double finest_wall = 0.0;
  for (const StudyPoint& p : a.points)
    if (p.ok) finest_wall = std::max(finest_wall, p.wall_s);
  if (best.wall_s > 0 && finest_wall > best.wall_s)
    s << " (the dearest variant took " << fixed(finest_wall, 3) << " s, " << fixed(finest_wall / best.wall_s, 3)
      << "x as long)";
  return s.str();
}

/// log10(error %) against log10(wall time), the Pareto front joined.
void writeStudyPlot(const StudyOptions& o, const StudyAnalysis& a, const std::string& name,
                    const std::filesystem::path& png) {
  // Up to 6 variants each get a colour (the front takes the 7th) and their values in the legend; more share one series.
  std::vector<PlotSeries> series;
  PlotSeries front{"Pareto front", {}, {}, PlotSeries::Style::Line};  // over the coloured points
  std::vector<std::pair<double, double>> f;
  const bool relative = a.reference != 0.0;  // a reference of 0: the figure is an error already
  std::size_t plotted = 0;
  for (const StudyPoint& p : a.points) plotted += p.ok && !p.is_reference;
  PlotSeries all{"variants", {}, {}, PlotSeries::Style::Points};
  for (const StudyPoint& p : a.points) {
    const double e = relative ? p.error_pct : p.error;
    if (!p.ok || p.is_reference || !(e > 0) || !(p.wall_s > 0)) continue;  // log scale: no zero error
    if (plotted <= 6) {
      std::string label;
      for (std::size_t k = 0; k < p.values.size(); ++k) label += (k ? ", " : "") + p.values[k];
      series.push_back({label, {std::log10(p.wall_s)}, {std::log10(e)}, PlotSeries::Style::Points});
    } else {
      all.x.push_back(std::log10(p.wall_s));
      all.y.push_back(std::log10(e));
    }
    if (p.pareto) f.emplace_back(std::log10(p.wall_s), std::log10(e));
  }
  if (!all.x.empty()) series.push_back(all);
  std::sort(f.begin(), f.end());
  for (const auto& [x, y] : f) front.x.push_back(x), front.y.push_back(y);
  series.insert(series.begin(), front);  // drawn first, under the points
  PlotSpec spec;
  spec.title = name + ": error of " + o.figure + " against run time (legend: " + o.runs.vary.front().first +
               (o.runs.vary.size() > 1 ? ", ..." : "") + ")";
  spec.x_label = "log10 wall time (s)";
  spec.y_label = relative ? "log10 error (%)" : "log10 |" + o.figure + "|";
  spec.series = series;
  writePlot(spec, png);
}

}  // namespace

StudyAnalysis analyseStudy(std::vector<StudyPoint> points, std::optional<double> reference, double tolerance_pct) {
  StudyAnalysis a;
  if (reference) {
    a.reference = *reference;
  } else {
    a.reference = kNaN;
    for (auto it = points.rbegin(); it != points.rend(); ++it)
      if (it->ok) {
        it->is_reference = true;
        a.reference = it->figure;
        break;
      }
  }
  for (StudyPoint& p : points) {
    p.error = p.ok ? std::abs(p.figure - a.reference) : kNaN;
    p.error_pct = p.ok && a.reference != 0.0 ? 100.0 * p.error / std::abs(a.reference) : kNaN;
  }
  // Pareto: no other ok point is at most as dear and at most as far, and better in one.
  const auto err = [&](const StudyPoint& p) { return std::isfinite(p.error_pct) ? p.error_pct : p.error; };
  for (StudyPoint& p : points) {
    if (!p.ok || !std::isfinite(err(p))) continue;
    p.pareto = std::none_of(points.begin(), points.end(), [&](const StudyPoint& q) {
      return q.ok && std::isfinite(err(q)) && q.wall_s <= p.wall_s && err(q) <= err(p) &&
             (q.wall_s < p.wall_s || err(q) < err(p));
    });
  }
  bool tail_within = true;  // every ok point after k is within the tolerance
  for (std::size_t k = points.size(); k-- > 0;) {
    const StudyPoint& p = points[k];
    if (!p.ok) continue;
    tail_within = tail_within && err(p) <= tolerance_pct;
    if (!tail_within) break;
    if (!a.recommended || p.wall_s < points[*a.recommended].wall_s) a.recommended = k;
  }
  a.points = std::move(points);
  return a;
}

namespace {

/// One row of the study: a variant with its seeds (o.seeds consecutive runs, the
/// seed varying fastest) or a single run.
struct Row {
  StudyPoint point;
  std::string status;
  std::vector<std::size_t> members;  // indices into the runs
};

std::vector<Row> rowsOf(const StudyOptions& o, const std::vector<Variant>& done) {
  const auto per = static_cast<std::size_t>(std::max(1, o.seeds));
  std::vector<Row> rows;
  for (std::size_t first = 0; first < done.size(); first += per) {
    Row row;
    StudyPoint& p = row.point;
    p.values = done[first].values;
    if (per > 1) p.values.pop_back();  // the seed
    std::vector<double> figures;
    double wall = 0.0;
    std::string failure;
    for (std::size_t k = first; k < std::min(done.size(), first + per); ++k) {
      row.members.push_back(k);
      const Variant& v = done[k];
      const double f = number(lookup(v.results, o.figure));
      if (v.code == kExitOk && std::isfinite(f)) {
        figures.push_back(f);
        wall += number(lookup(v.results, "wall_time_s.total"));
      } else if (failure.empty()) {
        failure = v.code != kExitOk ? v.status : "no figure";
      }
    }
    p.runs = static_cast<int>(figures.size());
    p.ok = !figures.empty() && failure.empty();
    const SampleStatistics stats = sampleStatistics(figures);
    p.figure = stats.mean;
    p.wall_s = figures.empty() ? kNaN : wall / static_cast<double>(figures.size());  // per run
    p.scatter = stats.sd;
    if (failure.empty()) row.status = "ok";
    else if (per > 1) row.status = std::to_string(figures.size()) + " of " + std::to_string(row.members.size()) + " ok; " + failure;
    else row.status = failure;
    rows.push_back(row);
  }
  return rows;
}

/// |error| over the standard error of the difference to the reference: below ~2
/// the variant cannot be told from the reference with these seeds.
double errorOverScatter(const StudyPoint& p, const StudyPoint* ref) {
  if (!ref || p.is_reference || !(p.runs > 1) || !(ref->runs > 1)) return kNaN;
  const double se = std::sqrt(p.scatter * p.scatter / p.runs + ref->scatter * ref->scatter / ref->runs);
  return se > 0 ? p.error / se : kNaN;
}

/// The study's table, study.json, plot and recommendation from what its runs left.
int reportStudy(const std::filesystem::path& dir, const StudyOptions& o, const std::vector<PlannedRun>& runs,
                const std::vector<Variant>& done, const std::string& name, std::ostream& log) {
  const std::vector<Row> rows_in = rowsOf(o, done);
  std::vector<StudyPoint> points;
  for (const Row& r : rows_in) points.push_back(r.point);
  const StudyAnalysis a = analyseStudy(points, o.reference, o.tolerance_pct);
  const bool seeded = o.seeds > 1;
  const std::string reference_text =
      o.reference ? "the reference value " + fixed(a.reference, 6) : "the finest variant (" + fixed(a.reference, 6) + ")";
  const StudyPoint* ref = nullptr;
  for (const StudyPoint& p : a.points)
    if (p.is_reference) ref = &p;

  std::vector<std::string> header;
  for (std::size_t k = 0; k + (seeded ? 1 : 0) < o.runs.vary.size(); ++k) header.push_back(o.runs.vary[k].first);
  header.push_back(seeded ? o.figure + " (mean)" : o.figure);
  if (seeded)
    for (const char* h : {"scatter", "runs", "error_over_scatter"}) header.push_back(h);
  for (const char* h : {"error", "error_pct", seeded ? "wall_time_s (per run)" : "wall_time_s", "pareto", "reference", "status"})
    header.push_back(h);
  std::vector<std::vector<std::string>> rows;
  json rows_json = json::array();
  bool all_within_scatter = seeded;
  for (std::size_t k = 0; k < a.points.size(); ++k) {
    const StudyPoint& p = a.points[k];
    const double t = errorOverScatter(p, ref);
    if (!p.is_reference) all_within_scatter = all_within_scatter && std::isfinite(t) && t < 2.0;
    std::vector<std::string> row = p.values;
    row.push_back(fixed(p.figure, 8));
    if (seeded)
      for (const std::string& c : {fixed(p.scatter, 4), std::to_string(p.runs), fixed(t, 3)}) row.push_back(c);
    for (const std::string& c : {fixed(p.error, 4), fixed(p.error_pct, 4), fixed(p.wall_s, 4),
                                 std::string(p.pareto ? "yes" : ""), std::string(p.is_reference ? "yes" : ""),
                                 rows_in[k].status})
      row.push_back(c);
    rows.push_back(row);
    json values = json::object();
    for (std::size_t j = 0; j < p.values.size(); ++j) values[o.runs.vary[j].first] = p.values[j];
    json entry = {{"values", values},
                  {"folder", "runs/" + runs[rows_in[k].members.front()].name},
                  {"figure", detail::finiteOrNull(p.figure)},
                  {"error", detail::finiteOrNull(p.error)},
                  {"error_pct", detail::finiteOrNull(p.error_pct)},
                  {"wall_time_s", detail::finiteOrNull(p.wall_s)},
                  {"pareto", p.pareto},
                  {"reference", p.is_reference},
                  {"status", rows_in[k].status}};
    if (seeded) {
      json each = json::array();
      for (std::size_t m : rows_in[k].members)
        each.push_back({{"seed", done[m].values.back()},
                        {"folder", "runs/" + runs[m].name},
                        {"figure", detail::finiteOrNull(number(lookup(done[m].results, o.figure)))},
                        {"wall_time_s", detail::finiteOrNull(number(lookup(done[m].results, "wall_time_s.total")))},
                        {"status", done[m].status}});  // inspectRuns: "ok", "exit N: ...", "missing"
      entry["runs"] = each;
      entry["scatter"] = detail::finiteOrNull(p.scatter);
      entry["error_over_scatter"] = detail::finiteOrNull(t);
    }
    rows_json.push_back(entry);
  }
  writeTable(header, rows, dir / "study.csv", log);
  std::string line = recommendation(o, a, reference_text);
  if (seeded && ref) {
    line += "; " + std::to_string(o.seeds) + " seeds a variant, the reference's seed scatter " +
            fixed(ref->scatter, 4) + (a.reference != 0.0 ? " (" + fixed(100.0 * ref->scatter / std::abs(a.reference), 3) + " %)" : "");
    if (all_within_scatter) line += "; every variant is within twice the standard error of the reference: the seeds cannot tell them apart";
  }
  log << "recommendation: " << line << "\n";
  json out = {{"scene", name},
              {"description", o.description},
              {"figure", o.figure},
              {"reference", {{"kind", o.reference ? "value" : "finest"},
                             {"value", detail::finiteOrNull(a.reference)}}},
              {"tolerance_pct", o.tolerance_pct},
              {"seeds", o.seeds},
              {"variants", rows_json},
              {"recommended", a.recommended ? json("runs/" + runs[rows_in[*a.recommended].members.front()].name) : json(nullptr)},
              {"recommendation", line},
              {"complete", allOk(done)}};
  writeAtomically(dir / "study.json", jsonText(out));
  try {
    writeStudyPlot(o, a, name, dir / "study.png");
  } catch (const std::exception& e) {
    log << "study: no plot (" << e.what() << ")\n";
  }
  refreshSetReport(dir, log, "study");
  log << "study: table " << (dir / "study.csv").string() << ", plot " << (dir / "study.png").string() << ", page "
      << (dir / "report.html").string() << "\n";
  return allOk(done) ? kExitOk : kExitRunsFailed;
}

}  // namespace

int runStudy(const StudyOptions& options, std::ostream& log) {
  StudyOptions o = options;
  if (o.runs.vary.empty()) {
    log << "error: study: give at least one --vary key=a,b,c (from the cheapest to the finest value)\n";
    return kExitBadInput;
  }
  if (o.figure.empty()) {
    log << "error: study: give --figure, a results.json path such as restitution or tracking.rms_error_pct\n";
    return kExitBadInput;
  }
  if (o.seeds > 1) {
    // Seeds as the innermost (fastest) dimension, from the scene's own seed up.
    for (const auto& [key, values] : o.runs.vary)
      if (key == "scene.seed") {
        log << "error: study: --seeds repeats every variant with its own seeds; do not also --vary scene.seed\n";
        return kExitBadInput;
      }
    std::uint64_t base = 1;
    try {
      base = sceneFor(o.runs, expandVariants(o.runs).front().values).run.seed;
    } catch (const SceneError&) {
      // reported with the runs below
    }
    std::vector<std::string> seeds;
    for (int k = 0; k < o.seeds; ++k) seeds.push_back(std::to_string(base + static_cast<std::uint64_t>(k)));
    o.runs.vary.emplace_back("scene.seed", seeds);
  }
  // Validated before anything runs: an invalid variant is listed as failed (exit
  // 2) and costs nothing; when none is valid, nothing is written.
  const std::vector<PlannedRun> runs = planRuns(o.runs);
  const auto valid = std::find_if(runs.begin(), runs.end(), [](const PlannedRun& r) { return r.invalid.empty(); });
  if (valid == runs.end()) {
    log << "error: " << runs.front().invalid << "\n";
    return kExitBadInput;
  }
  const Scene first = sceneFor(o.runs, valid->values);
  const std::filesystem::path dir = outDirFor(o.runs, first, "-study");
  json what = {{"kind", "study"},
               {"figure", o.figure},
               {"reference", o.reference ? json(*o.reference) : json("finest")},
               {"tolerance_pct", o.tolerance_pct},
               {"seeds", o.seeds},
               {"description", o.description}};
  writePlanFiles(dir, o.runs, runs, what);
  log << "study of " << first.run.name << ": " << o.figure << " for " << runs.size() << " variants into "
      << dir.string() << "\n";
  if (!o.description.empty()) log << "  " << o.description << "\n";
  if (o.runs.plan_only) return reportPlan(dir, runs, "study", log);
  const int code = executeRuns(dir, o.runs, runs, log);
  const int report = reportStudy(dir, o, runs, inspectRuns(dir, runs), first.run.name, log);
  return code != kExitOk ? code : report;
}

namespace detail {

int collectStudy(const std::filesystem::path& dir, const SweepOptions& runs_options, const json& plan,
                 const std::vector<PlannedRun>& runs, const std::vector<Variant>& done, std::ostream& log) {
  StudyOptions o;
  o.runs = runs_options;
  o.figure = plan.value("figure", "");
  if (plan.contains("reference") && plan["reference"].is_number()) o.reference = plan["reference"].get<double>();
  o.tolerance_pct = plan.value("tolerance_pct", o.tolerance_pct);
  o.description = plan.value("description", "");
  o.seeds = plan.value("seeds", 1);
  return reportStudy(dir, o, runs, done, std::filesystem::path(o.runs.scene).stem().string(), log);
}

}  // namespace detail

std::filesystem::path builtinStudyDir() { return std::filesystem::path(ROCKLAB_ASSET_DIR) / "studies"; }

std::optional<std::filesystem::path> findStudyFile(const std::string& name_or_path) {
  std::filesystem::path p(name_or_path);
  if (!std::filesystem::exists(p) && p.extension().empty() && p.parent_path().empty())
    p = builtinStudyDir() / (name_or_path + ".toml");
  if (!std::filesystem::is_regular_file(p) || p.extension() != ".toml") return std::nullopt;
  try {
    const toml::table t = toml::parse_file(p.string());
    if (t.contains("study")) return p;
  } catch (const toml::parse_error&) {
    return std::nullopt;  // not ours: the scene reader will report it
  }
  return std::nullopt;
}

StudyOptions loadStudyFile(const std::filesystem::path& file) {
  toml::table root;
  try {
    root = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw SceneError(file.string() + ": " + std::string(e.description()));
  }
  TableReader top(root, "");
  auto t = top.table("study");
  if (!t) throw SceneError(file.string() + ": no [study] table");
  StudyOptions o;
  o.description = t->string("description", "");
  std::string scene = t->requiredString("scene");
  // A scene file named relative to the study file; else a built-in scene name.
  if (std::filesystem::path(scene).extension() == ".toml" && std::filesystem::path(scene).is_relative())
    scene = (file.parent_path() / scene).string();
  o.runs.scene = scene;
  o.figure = t->requiredString("figure");
  if (t->has("reference") && t->raw()["reference"].is_number()) {
    o.reference = t->number("reference", 0.0);
  } else {
    t->string("reference", "finest", {"finest"});
  }
  o.tolerance_pct = t->number("tolerance_pct", o.tolerance_pct, Range::positive());
  o.seeds = static_cast<int>(t->integer("seeds", 1, Range::closed(1, 1000)));
  o.runs.overrides = t->stringList("set");
  for (TableReader& v : t->tableArray("vary")) {
    const std::string key = v.requiredString("key");
    std::vector<std::string> values = v.valueTextList("values");
    if (values.empty()) v.fail("values", "give at least one value");
    o.runs.vary.emplace_back(key, values);
    v.finish();
  }
  if (o.runs.vary.empty()) t->fail("vary", "give at least one [[study.vary]] with key and values");
  t->finish();
  top.finish();
  return o;
}

}  // namespace rocklab::experiments
