#include "analysis/profiles_command.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "analysis/plot.h"
#include "analysis/sweep_table.h"
#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/json_text.h"
#include "common/run_comparison.h"
#include "rocklab/experiments/run.h"
#include "sets/run_set.h"

namespace rocklab::experiments {

namespace {

struct ProfileInputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct MarkerPoint {
  int column = 0, row = 0;
  double height_mm = NAN, velocity = NAN;  // start height above the base; mean velocity over the measured travel
};

struct ChuteRun {
  std::string label;
  std::filesystem::path dir;
  std::vector<MarkerPoint> markers;
  std::map<int, double> column_distance_m, column_mean;  // by column number
  std::vector<double> discharge_t, discharge_kg;       // after the gate
  nlohmann::json figures;                              // the table's row
};

double numberAt(const nlohmann::json& j, const std::string& key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw ProfileInputError(where + ": no key '" + key + "'");
  const nlohmann::json& v = j.at(key);
  if (v.is_null()) return NAN;  // a marker that never travelled its distance
  if (!v.is_number()) throw ProfileInputError(where + "." + key + ": " + v.dump() + " is not a number");
  return v.get<double>();
}

ChuteRun readRun(const std::filesystem::path& dir) {
  const nlohmann::json r = detail::readJsonFile(dir / "results.json");
  if (r.is_discarded()) throw ProfileInputError("cannot read it as JSON (a chute run's folder holds it)");
  if (!r.is_object() || !r.contains("chute") || !r.contains("markers") || !r.at("markers").is_array())
    throw ProfileInputError("no keys 'chute' and 'markers' (not a chute run)");
  ChuteRun run;
  run.dir = dir;
  const nlohmann::json& markers = r.at("markers");
  for (std::size_t k = 0; k < markers.size(); ++k) {
    const std::string where = "markers." + std::to_string(k);
    const nlohmann::json& m = markers[k];
    const nlohmann::json start = m.is_object() ? m.value("start_position_m", nlohmann::json()) : nlohmann::json();
    if (!start.is_array() || start.size() != 3 || !start[2].is_number())
      throw ProfileInputError(where + ".start_position_m: not [x, y, z] in m");
    MarkerPoint p;
    p.column = static_cast<int>(numberAt(m, "column", where));
    p.row = static_cast<int>(numberAt(m, "row", where));
    p.height_mm = 1e3 * start[2].get<double>();
    p.velocity = numberAt(m, "truth_velocity_mps", where);
    run.markers.push_back(p);
  }
  if (r.contains("profile") && r.at("profile").is_array())
    for (std::size_t k = 0; k < r.at("profile").size(); ++k) {
      const std::string where = "profile." + std::to_string(k);
      const nlohmann::json& c = r.at("profile")[k];
      const int column = static_cast<int>(numberAt(c, "column", where));
      run.column_distance_m[column] = numberAt(c, "distance_m", where);
      run.column_mean[column] = numberAt(c, "mean_truth_velocity_mps", where);
    }
  // The discharge curve the run wrote beside results.json (time after the gate, kg);
  // none when the file is missing or empty (the gate never opened).
  const std::filesystem::path discharge = dir / "discharge.csv";
  std::error_code ec;
  if (std::filesystem::is_regular_file(discharge, ec) && std::filesystem::file_size(discharge, ec) > 0) {
    try {
      const SweepTable t = readCsvTable(discharge);
      const std::size_t time = t.column("time_after_gate_s"), mass = t.column("discharged_mass_kg");
      for (const std::vector<std::string>& row : t.rows) {
        const auto ti = SweepTable::numberIn(row, time), mi = SweepTable::numberIn(row, mass);
        if (!ti || !mi) throw ProfileInputError("discharge.csv: a row is not time_after_gate_s,discharged_mass_kg");
        run.discharge_t.push_back(*ti);
        run.discharge_kg.push_back(*mi);
      }
    } catch (const std::invalid_argument& e) {  // unreadable, or a column missing: named by the table reader
      throw ProfileInputError(e.what());
    }
  }
  const nlohmann::json& c = r.at("chute");
  run.figures = {{"scene", r.value("scene", "")},
                 {"clearance_time_s", r.value("clearance_time_s", nlohmann::json())},
                 {"jammed", r.value("jammed", nlohmann::json())},
                 {"bodies", c.value("bodies", nlohmann::json())},
                 {"discharged_bodies", c.value("discharged_bodies", nlohmann::json())},
                 {"discharged_mass_kg", c.value("discharged_mass_kg", nlohmann::json())},
                 {"deposit_inclination_deg", c.value("deposit_inclination_deg", nlohmann::json())},
                 {"seed", r.value("seed", nlohmann::json())}};
  return run;
}

}  // namespace

int runProfilesCommand(const RunComparisonOptions& o, std::ostream& out, std::ostream& err) {
  if (const std::string problem = detail::runLabelsProblem(o.runs.size(), o.labels.size()); !problem.empty()) {
    err << "error: profiles: " << problem << "\n";
    return kExitBadInput;
  }
  std::vector<ChuteRun> runs;
  for (std::size_t k = 0; k < o.runs.size(); ++k) {
    try {
      runs.push_back(readRun(o.runs[k]));
    } catch (const ProfileInputError& e) {
      err << "error: " << (o.runs[k] / "results.json").string() << ": " << e.what() << '\n';
      return kExitBadInput;
    }
    runs.back().label = detail::runLabel(o.runs, o.labels, k);
  }
  std::map<int, double> distance_m;  // every column of any run, with its distance from the outlet
  for (const ChuteRun& run : runs)
    for (const auto& [column, d] : run.column_distance_m) distance_m.emplace(column, d);

  // The table: one row a marker (the points of the plots), and one a run for the summary.
  std::ostringstream csv;
  csv << "label,run,column,column_distance_m,row,start_height_mm,truth_velocity_mps\n";
  nlohmann::json table = nlohmann::json::array();
  for (const ChuteRun& run : runs) {
    for (const MarkerPoint& m : run.markers)
      csv << detail::csvCell(run.label) << ',' << detail::csvCell(run.dir.string()) << ',' << m.column << ','
          << detail::cell(distance_m.count(m.column) ? nlohmann::json(distance_m[m.column]) : nlohmann::json())
          << ',' << m.row << ',' << m.height_mm << ',' << detail::cell(detail::finiteOrNull(m.velocity)) << '\n';
    nlohmann::json row = run.figures;
    row["label"] = run.label;
    row["run"] = run.dir.string();
    nlohmann::json means = nlohmann::json::array();
    for (const auto& [column, v] : run.column_mean)
      means.push_back({{"column", column}, {"distance_m", run.column_distance_m.at(column)},
                       {"mean_truth_velocity_mps", detail::finiteOrNull(v)}});
    row["columns"] = means;
    table.push_back(row);
  }

  // One plot a column: velocity against starting height, a series a run (same colour in every plot).
  std::vector<std::pair<std::filesystem::path, PlotSpec>> plots;
  std::vector<PlotSpec> row;  // profiles.png's panels
  double v_lo = INFINITY, v_hi = -INFINITY;
  for (const auto& [column, d] : distance_m) {
    PlotSpec spec;
    spec.title = "markers of column " + std::to_string(column) + " (" + std::to_string(std::lround(d * 1e3)) +
                 " mm from the outlet): velocity over their first travel (DEM truth)";
    spec.x_label = "velocity along the base (m/s)";
    spec.y_label = "starting height above the base (mm)";
    for (std::size_t k = 0; k < runs.size(); ++k) {
      std::vector<std::pair<double, double>> points;  // (height, velocity), drawn bottom up
      for (const MarkerPoint& m : runs[k].markers)
        if (m.column == column) points.emplace_back(m.height_mm, m.velocity);
      std::sort(points.begin(), points.end());
      PlotSeries s{runs[k].label, {}, {}, PlotSeries::Style::LinePoints};
      for (const auto& [z, v] : points) {
        s.x.push_back(v);
        s.y.push_back(z);
      }
      s.colour = static_cast<int>(k);
      spec.series.push_back(s);
    }
    plots.emplace_back(o.out_dir / ("profile_column_" + std::to_string(column) + ".png"), spec);
    // The same column as a panel of profiles.png: the columns side by side on one
    // velocity axis (a zone each in the zoned chute), how they differ read at a glance.
    PlotSpec& panel = row.emplace_back(spec);
    panel.title = "column " + std::to_string(column) + ", " + std::to_string(std::lround(d * 1e3)) +
                  " mm from the outlet (DEM truth)";
    panel.width = 560;
    panel.height = 520;
    for (const PlotSeries& s : spec.series)
      for (const double v : s.x)
        if (std::isfinite(v)) v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
  }
  if (v_hi > v_lo)
    for (PlotSpec& panel : row) panel.x_range = std::pair{v_lo - 0.05 * (v_hi - v_lo), v_hi + 0.05 * (v_hi - v_lo)};
  PlotSpec discharge;
  discharge.title = "discharged mass after the gate opened";
  discharge.x_label = "time after the gate opened (s)";
  discharge.y_label = "discharged mass (kg)";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    PlotSeries s{runs[k].label, {0.0}, {0.0}, PlotSeries::Style::Line};
    s.x.insert(s.x.end(), runs[k].discharge_t.begin(), runs[k].discharge_t.end());
    s.y.insert(s.y.end(), runs[k].discharge_kg.begin(), runs[k].discharge_kg.end());
    s.colour = static_cast<int>(k);
    discharge.series.push_back(s);
  }
  plots.emplace_back(o.out_dir / "discharge.png", discharge);
  try {
    std::filesystem::create_directories(o.out_dir);
    detail::writeAtomically(o.out_dir / "profiles.csv", csv.str());
    detail::writeAtomically(o.out_dir / "profiles.json", detail::jsonText({{"runs", table}}));
    for (const auto& [png, spec] : plots) writePlot(spec, png);
    if (row.size() > 1) writePlotRow(row, o.out_dir / "profiles.png");
  } catch (const std::exception& e) {
    err << "error: profiles: " << e.what() << '\n';
    return kExitFailed;
  }
  out << std::left << std::setw(28) << "run" << std::right << std::setw(12) << "clearance_s" << std::setw(8) << "jammed";
  for (const auto& [column, d] : distance_m) out << std::setw(14) << ("col" + std::to_string(column) + "_m/s");
  out << '\n';
  for (const ChuteRun& run : runs) {
    out << std::left << std::setw(28) << run.label << std::right << std::setw(12)
        << detail::cell(run.figures["clearance_time_s"]) << std::setw(8) << detail::cell(run.figures["jammed"]);
    for (const auto& [column, d] : distance_m) {
      const auto it = run.column_mean.find(column);
      out << std::setw(14) << (it == run.column_mean.end() || !std::isfinite(it->second) ? std::string("-") : detail::cell(it->second));
    }
    out << '\n';
  }
  out << "wrote " << (o.out_dir / "profiles.csv").string() << ", profiles.json, " << distance_m.size()
      << " profile_column_N.png" << (distance_m.size() > 1 ? ", profiles.png (the columns side by side)" : "")
      << " and discharge.png\n";
  return 0;
}

}  // namespace rocklab::experiments
