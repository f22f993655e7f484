#include "analysis/sweeps_command.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <sstream>

#include "analysis/plot.h"
#include "analysis/sweep_sets.h"
#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/json_text.h"
#include "rocklab/experiments/run.h"
#include "scene/scene_keys.h"
#include "sets/run_set.h"

namespace rocklab::experiments {

namespace {

using json = nlohmann::json;
using detail::SweepSet;
using detail::SweepSetError;

/// A sweep's rows with the plotted x and figure: x is the first key's value (over the
/// row's own --x-over figure), NaN where a cell is not a number.
struct SeriesRows {
  std::vector<double> x, y;
  std::vector<std::size_t> order;  // rows by x, those without one last
};

std::optional<double> numberAt(const SweepSet& s, const std::vector<std::string>& row, const std::string& column) {
  return SweepTable::numberIn(row, s.table.column(column));
}

SeriesRows seriesOf(const SweepSet& s, const std::string& figure) {
  SeriesRows r;
  for (const auto& row : s.table.rows) {
    double x = numberAt(s, row, s.keys.front()).value_or(NAN);
    if (!s.x_over.empty()) x /= numberAt(s, row, s.x_over).value_or(NAN);
    r.x.push_back(x);
    r.y.push_back(figure.empty() ? NAN : numberAt(s, row, figure).value_or(NAN));
  }
  r.order.resize(r.x.size());
  std::iota(r.order.begin(), r.order.end(), std::size_t{0});
  std::stable_sort(r.order.begin(), r.order.end(), [&](std::size_t a, std::size_t b) {
    return std::isnan(r.x[b]) ? !std::isnan(r.x[a]) : r.x[a] < r.x[b];
  });
  return r;
}

/// The figure to plot: the one asked for, else the first figure column (not the --x-over
/// divisor) with a number in any sweep.
std::string pickFigure(const std::vector<SweepSet>& sets, const std::string& asked) {
  const std::vector<std::string> figures = detail::figureColumns(sets.front());
  const auto hasNumbers = [&](const std::string& f) {
    return std::any_of(sets.begin(), sets.end(), [&](const SweepSet& s) {
      return std::any_of(s.table.rows.begin(), s.table.rows.end(),
                         [&](const auto& row) { return numberAt(s, row, f).has_value(); });
    });
  };
  if (!asked.empty()) {
    if (std::find(figures.begin(), figures.end(), asked) == figures.end() || !hasNumbers(asked)) {
      std::vector<std::string> allowed;
      for (const std::string& f : figures)
        if (hasNumbers(f)) allowed.push_back(f);
      throw SweepSetError("--figure " + asked + ": not a figure column with numbers of " +
                          sets.front().table.file.string() + " (allowed: " + detail::sortedNames(allowed) + ")");
    }
    return asked;
  }
  for (const std::string& f : figures)
    if (f != sets.front().x_over && hasNumbers(f)) return f;
  return {};
}

}  // namespace

int runSweepsCommand(const RunComparisonOptions& o, const std::string& figure_name, std::ostream& out,
                     std::ostream& err) {
  if (const std::string problem = detail::runLabelsProblem(o.runs.size(), o.labels.size()); !problem.empty()) {
    err << "error: sweeps: " << problem << "\n";
    return kExitBadInput;
  }
  std::vector<SweepSet> sets;
  std::string figure;
  try {
    for (std::size_t k = 0; k < o.runs.size(); ++k) {
      sets.push_back(detail::readSweepSet(o.runs[k]));
      sets.back().label = detail::runLabel(o.runs, o.labels, k);
    }
    detail::checkSameShape(sets, "a series each");
    figure = pickFigure(sets, figure_name);
  } catch (const SweepSetError& e) {
    err << "error: sweeps: " << e.what() << '\n';
    return kExitBadInput;
  }
  const SweepSet& first = sets.front();
  const std::string x_name = first.keys.front() + (first.x_over.empty() ? "" : " / " + first.x_over);

  // sweeps.csv: the first sweep's columns (the others' found by name), x, a row a run.
  std::ostringstream csv;
  csv << "sweep";
  for (const std::string& h : first.table.header) csv << ',' << detail::csvCell(h);
  if (!first.x_over.empty()) csv << ',' << detail::csvCell(x_name);
  csv << '\n';
  PlotSpec spec;
  spec.title = (figure.empty() ? std::string("sweeps") : figure) + " against " + x_name + ": a series a sweep";
  spec.x_label = first.x_over.empty() ? withSceneKeyUnit(x_name) : x_name;
  spec.y_label = figure;
  json sweeps = json::array();
  for (const SweepSet& s : sets) {
    const SeriesRows r = seriesOf(s, figure);
    PlotSeries series{s.label, {}, {}, PlotSeries::Style::LinePoints};
    json rows = json::array();
    for (std::size_t i : r.order) {
      const auto& row = s.table.rows[i];
      csv << detail::csvCell(s.label);
      json cells = json::object();
      for (const std::string& h : first.table.header) {
        const std::size_t c = s.table.column(h);
        const std::string value = c < row.size() ? row[c] : std::string();
        csv << ',' << detail::csvCell(value);
        cells[h] = value;
      }
      if (!first.x_over.empty()) csv << ',' << detail::cell(detail::finiteOrNull(r.x[i]));
      csv << '\n';
      rows.push_back({{"x", detail::finiteOrNull(r.x[i])}, {"y", detail::finiteOrNull(r.y[i])}, {"cells", cells}});
      series.x.push_back(r.x[i]);
      series.y.push_back(r.y[i]);  // NaN: the line breaks there
    }
    spec.series.push_back(series);
    sweeps.push_back({{"label", s.label}, {"sweep", s.dir.string()}, {"runs_not_ok", s.table.not_ok}, {"rows", rows}});
  }
  const json summary = {{"x", x_name}, {"figure", figure.empty() ? json() : json(figure)}, {"sweeps", sweeps}};
  try {
    std::filesystem::create_directories(o.out_dir);
    detail::writeAtomically(o.out_dir / "sweeps.csv", csv.str());
    detail::writeAtomically(o.out_dir / "sweeps.json", detail::jsonText(summary));
    if (!figure.empty()) writePlot(spec, o.out_dir / "sweeps.png");
  } catch (const std::exception& e) {
    err << "error: sweeps: " << e.what() << '\n';
    return kExitFailed;
  }

  // The console table: a row a run, its sweep, x and the plotted figure.
  out << std::left << std::setw(20) << "sweep" << ' ' << std::setw(36) << x_name << ' ' << (figure.empty() ? "-" : figure)
      << '\n';
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const json& rows = sweeps[k]["rows"];
    for (const json& row : rows)
      out << std::left << std::setw(20) << sets[k].label << ' ' << std::setw(36) << detail::cell(row["x"]) << ' '
          << (row["y"].is_null() ? std::string("-") : detail::cell(row["y"])) << '\n';
    if (sets[k].table.not_ok) out << "note: " << sets[k].label << ": " << sets[k].table.not_ok << " run(s) not ok, left out\n";
  }
  out << "wrote " << (o.out_dir / "sweeps.csv").string() << ", sweeps.json"
      << (figure.empty() ? " (no figure with numbers: no plot)" : ", sweeps.png") << '\n';
  return 0;
}

}  // namespace rocklab::experiments
