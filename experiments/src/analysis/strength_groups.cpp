#include "analysis/strength_groups.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "analysis/batch_curves.h"
#include "analysis/plot.h"
#include "analysis/sample_statistics.h"
#include "analysis/sweep_table.h"
#include "analysis/weibull.h"
#include "common/atomic_file.h"
#include "common/json_text.h"
#include "rocklab/experiments/run.h"  // exit codes

namespace rocklab::experiments {

namespace {

std::string text(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

/// The mean of the values; NaN for none.
double meanOf(const std::vector<double>& v) { return sampleStatistics(v).mean; }

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// One group: the rows of the sweep with the same value of the grouping key.
struct Group {
  std::string value;
  std::vector<double> strengths;                  // MPa
  std::map<std::size_t, std::vector<double>> columns;  // other numeric columns, by index
};

}  // namespace

int strengthGroupsCommand(const std::filesystem::path& dir, const StrengthGroupOptions& o, std::ostream& log) {
  SweepTable table;
  std::size_t strength_col = 0, group_col = 0, size_col = 0;
  try {
    table = readSweepTable(dir);
    strength_col = table.column(o.strength_column);
    group_col = table.column(o.group_by);
    if (!o.size_column.empty()) size_col = table.column(o.size_column);
  } catch (const std::invalid_argument& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  // Groups in the order their values first appear (the sweep's order).
  std::vector<Group> groups;
  for (const auto& row : table.rows) {
    const std::string value = group_col < row.size() ? row[group_col] : "";
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return x.value == value; });
    if (g == groups.end()) g = groups.insert(groups.end(), Group{value, {}, {}});
    const auto s = SweepTable::numberIn(row, strength_col);
    if (!s || *s <= 0) continue;
    g->strengths.push_back(*s);
    for (std::size_t k = 0; k < table.header.size(); ++k)
      if (k != strength_col && k != group_col)
        if (const auto v = SweepTable::numberIn(row, k)) g->columns[k].push_back(*v);
  }
  if (groups.empty()) {
    log << "error: " << table.file.string() << ": no run that ended normally\n";
    return kExitBadInput;
  }
  // The table: one row per group.
  std::vector<std::string> header{o.group_by, "runs", "mean_MPa", "stddev_MPa", "cov", "weibull_m",
                                  "weibull_sigma0_MPa", "weibull_r2"};
  std::vector<std::size_t> extra;  // other numeric columns, mean per group
  for (std::size_t k = 0; k < table.header.size(); ++k)
    if (k != strength_col && k != group_col && table.header[k] != "status") {
      extra.push_back(k);
      header.push_back("mean " + table.header[k]);
    }
  std::ostringstream csv;
  for (std::size_t k = 0; k < header.size(); ++k) csv << (k ? "," : "") << header[k];
  csv << "\n";
  nlohmann::json j;
  j["group_by"] = o.group_by;
  j["strength_column"] = o.strength_column;
  j["groups"] = nlohmann::json::array();
  PlotSeries means{"mean", {}, {}, PlotSeries::Style::Points};
  PlotSeries spread{"mean +/- 1 standard deviation", {}, {}, PlotSeries::Style::Points};
  std::vector<double> sizes, mean_strengths;
  bool numeric_groups = true;
  for (const Group& g : groups) {
    nlohmann::json row{{"value", g.value}, {"runs", g.strengths.size()}};
    std::vector<std::string> cells{g.value, std::to_string(g.strengths.size())};
    const SampleStatistics stats = sampleStatistics(g.strengths);
    const double mean = stats.mean, sd = stats.sd;
    row["mean_MPa"] = mean;
    row["stddev_MPa"] = sd;
    row["cov"] = sd / mean;
    cells.insert(cells.end(), {text(mean), text(sd), text(sd / mean)});
    if (g.strengths.size() >= 3) {
      const WeibullFit fit = fitWeibull(g.strengths);
      row["weibull_m"] = fit.modulus;
      row["weibull_sigma0_MPa"] = fit.sigma0;
      row["weibull_r2"] = fit.r2;
      cells.insert(cells.end(), {text(fit.modulus), text(fit.sigma0), text(fit.r2)});
    } else {
      cells.insert(cells.end(), {"", "", ""});
    }
    for (std::size_t k : extra) {
      const auto it = g.columns.find(k);
      const double m = it != g.columns.end() ? meanOf(it->second) : NAN;
      row["mean"][table.header[k]] = m;
      cells.push_back(std::isfinite(m) ? text(m) : "");
    }
    for (std::size_t k = 0; k < cells.size(); ++k) csv << (k ? "," : "") << cells[k];
    csv << "\n";
    j["groups"].push_back(row);
    const auto x = SweepTable::numberIn({g.value}, 0);
    numeric_groups = numeric_groups && x.has_value();
    const double gx = x ? *x : static_cast<double>(means.x.size());
    if (std::isfinite(mean)) {
      means.x.push_back(gx);
      means.y.push_back(mean);
      if (std::isfinite(sd))
        for (double y : {mean - sd, mean + sd}) {
          spread.x.push_back(gx);
          spread.y.push_back(y);
        }
      if (!o.size_column.empty()) {
        const auto it = g.columns.find(size_col);
        if (it != g.columns.end() && !it->second.empty()) {
          const double d = meanOf(it->second);
          sizes.push_back(endsWith(o.size_column, "_m") ? d * 1e3 : d);
          mean_strengths.push_back(mean);
        }
      }
    }
    log << "group " << o.group_by << " = " << g.value << ": " << g.strengths.size() << " runs, mean " << mean
        << " MPa, sd " << sd << " MPa, CoV " << sd / mean << "\n";
  }
  PlotSpec spec;
  spec.title = "strength against " + o.group_by;
  spec.x_label = numeric_groups ? o.group_by : o.group_by + " (in sweep order)";
  spec.y_label = o.strength_column;
  spec.series = {means, spread};
  if (!o.size_column.empty() && sizes.size() >= 2) {
    // Eq 5-5: sigma_av = a d^b, fitted on ln-ln axes.
    const PowerLawFit fit = fitPowerLaw(sizes, mean_strengths);
    const std::string unit = endsWith(o.size_column, "_m") ? "mm" : "its unit";
    j["size_effect"] = {{"size_column", o.size_column}, {"size_unit", unit}, {"a", fit.a}, {"b", fit.b},
                        {"r2", fit.r2}, {"law", "mean strength (MPa) = a d^b (Eq 5-5)"}};
    log << "size effect: mean strength = " << fit.a << " d^" << fit.b << " (d = mean " << o.size_column << " in "
        << unit << ", R^2 " << fit.r2 << "; the lab's Eq 5-5: 480.03 d^-1.1)\n";
    PlotSeries points{"group means", {}, {}, PlotSeries::Style::Points};
    PlotSeries line{"fit: " + text(fit.a) + " d^" + text(fit.b), {}, {}, PlotSeries::Style::Line};
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      points.x.push_back(std::log(sizes[k]));
      points.y.push_back(std::log(mean_strengths[k]));
      line.x.push_back(std::log(sizes[k]));
      line.y.push_back(std::log(fit.a) + fit.b * std::log(sizes[k]));
    }
    spec.title = "size effect (Eq 5-5): mean strength against size";
    spec.x_label = "ln(d / 1 " + unit + "), d = mean " + o.size_column;
    spec.y_label = "ln(mean strength / 1 MPa)";
    spec.series = {points, line};
  }
  detail::writeAtomically(dir / "strength_groups.csv", csv.str());
  detail::writeAtomically(dir / "strength_groups.json", detail::jsonText(j));
  try {
    writePlot(spec, dir / "strength_groups.png");
  } catch (const std::exception& e) {
    log << "strength groups: no plot (" << e.what() << ")\n";
  }
  log << "strength groups: " << (dir / "strength_groups.csv").string() << ", "
      << (dir / "strength_groups.png").string() << "\n";
  writeBatchForceCurves(dir, o.group_by, log);
  return kExitOk;
}

}  // namespace rocklab::experiments
