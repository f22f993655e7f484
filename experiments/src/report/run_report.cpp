#include "report/run_report.h"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <set>
#include <vector>

#include "common/atomic_file.h"
#include "common/json_text.h"
#include "report/html.h"
#include "report/set_report.h"
#include "rocklab/experiments/run.h"
#include "rocklab/sim/world.h"
#include "sets/run_set.h"

namespace rocklab::experiments::detail {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

/// A headline figure of an experiment: where results.json holds it, what it is, its
/// unit, and the reference the run reports beside it ("" = none). Only values the
/// run itself computes are shown: no laboratory value is typed in here.
struct Headline {
  const char* path;
  const char* label;
  const char* unit;
  const char* reference_path = "";
  const char* reference_label = "";
};

std::vector<Headline> headlinesOf(const std::string& experiment) {
  if (experiment == "drop")
    return {{"restitution", "coefficient of restitution (Eq 4-3)", "–", "drop.analytic_restitution",
             "analytic, Eq 4-4 at the scene's damping ratio"},
            {"drop.damping_ratio", "normal damping ratio β", "–"},
            {"drop.impact_speed_mps", "impact speed", "m/s"},
            {"drop.rebound_speed_mps", "rebound speed", "m/s"},
            {"drop.contact_time_s", "contact time", "s"}};
  if (experiment == "heap")
    return {{"angle_of_repose_deg", "angle of repose (geometric)", "°", "heap.photograph.angle_deg",
             "from the side photograph"},
            {"heap.angle_std_deg", "spread of the flank angles", "°"},
            {"heap.height_m", "heap height", "m"},
            {"heap.base_radius_m", "base radius", "m"},
            {"heap.settle_time_s", "settled at", "s"}};
  if (experiment == "chute")
    return {{"clearance_time_s", "clearance time", "s"},
            {"jammed", "jammed", ""},
            {"tracking.rms_error_pct", "tracked marker velocities: RMS error against the DEM truth", "%"},
            {"tracking.max_error_pct", "tracked marker velocities: largest error against the DEM truth", "%"},
            {"tracking.rms_error_mps", "tracked marker velocities: RMS error", "m/s"}};
  if (experiment == "zwick")
    return {{"strength_MPa", "strength (Eq 5-1)", "MPa"},
            {"peak_force_N", "peak force", "N"},
            {"zwick.platen_gap_at_peak_m", "platen gap at the peak", "m"},
            {"bonds_broken", "bonds broken", ""},
            {"bond_count", "bonds", ""},
            {"fragments.count", "fragments", ""},
            {"fragments.largest_fraction", "largest fragment (volume fraction)", "–"},
            {"porosity", "porosity", "–"},
            {"coordination_number", "coordination number", "–"}};
  return {};
}

/// A results.json value as a cell: numbers with 4 digits, text escaped, absent as "—".
std::string valueCell(const json& v) {
  if (v.is_number_integer()) return v.dump();
  if (v.is_number()) return shortNumber(v.get<double>());
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_string()) return htmlText(v.get<std::string>());
  if (v.is_null()) return "—";
  return htmlText(v.dump());
}

double numberAt(const json& r, const std::string& path) {
  const json v = lookup(r, path);
  return v.is_number() ? v.get<double>() : NAN;
}

std::string statusLine(const json& r) {
  const std::string status = r.value("status", std::string("unknown"));
  const bool ok = status == "completed";
  std::string s = "<p><span class=\"status" + std::string(ok ? "" : " bad") + "\">" + htmlText(status) + "</span>";
  if (r.contains("experiment_status")) s += " " + htmlText(r["experiment_status"].is_string() ? r["experiment_status"].get<std::string>() : "");
  s += "</p>\n";
  if (!ok) {
    const std::string why = r.contains("message") && r["message"].is_string() ? r["message"].get<std::string>()
                            : status == "interrupted" ? "stopped by Ctrl-C, SIGTERM or SIGHUP; the outputs so far are kept"
                                                      : "results.json gives no reason";
    s += "<div class=\"failure\"><strong>Run " + htmlText(status) + ":</strong> " + htmlText(why) +
         ". The figures below are those of the state it reached.</div>\n";
  }
  for (const json& w : r.value("warnings", json::array()))
    if (w.is_string()) s += "<div class=\"warning\">" + htmlText(w.get<std::string>()) + "</div>\n";
  return s;
}

std::string whatWasRun(const json& r) {
  const json settings = r.value("settings", json::object());
  std::vector<std::vector<std::string>> rows;
  auto add = [&](const std::string& what, const std::string& cell) { rows.push_back({htmlText(what), cell}); };
  add("scene", valueCell(r.value("scene", json())));
  if (settings.contains("description")) add("description", valueCell(settings["description"]));
  if (settings.contains("source")) add("scene file", valueCell(settings["source"]));
  add("experiment", r.contains("experiment") ? valueCell(r["experiment"]) : "none (a plain run)");
  if (settings.contains("end_time_s")) add("end time (s)", valueCell(settings["end_time_s"]));
  if (settings.contains("steps")) add("step limit", valueCell(settings["steps"]));
  add("seed", valueCell(r.value("seed", json())));
  if (r.contains("particles_at_start"))
    add("particles (balls) / clumps at the start", valueCell(r["particles_at_start"]) + " / " +
                                                       valueCell(r.value("clumps_at_start", json())));
  add("particles (balls) / clumps / walls at the end", valueCell(r.value("particles", json())) + " / " +
                                                           valueCell(r.value("clumps", json())) + " / " +
                                                           valueCell(r.value("walls", json())));
  add("time step dt (s)", valueCell(r.value("dt_s", json())));
  add("steps (this run)", valueCell(r.value("steps_this_run", json())));
  add("simulated time (s)", valueCell(r.value("simulated_time_s", json())));
  add("threads", valueCell(r.value("threads", json())));
  if (r.contains("modules") && r["modules"].is_array()) {
    std::string m;
    for (const json& x : r["modules"]) m += (m.empty() ? "" : ", ") + valueCell(x);
    add("modules", m);
  }
  add("rocklab commit (at build time)", settings.contains("commit") ? valueCell(settings["commit"]) : "unknown");
  add("state hash", valueCell(r.value("state_hash", json())));
  return htmlSection("What was run", htmlTable({"setting", "value"}, rows));
}

std::string headlineFigures(const json& r) {
  std::vector<std::vector<std::string>> rows;
  for (const Headline& h : headlinesOf(r.value("experiment", std::string()))) {
    const json v = lookup(r, h.path);
    if (v.is_null()) continue;
    std::string reference = "";
    if (*h.reference_path != '\0') {
      const json ref = lookup(r, h.reference_path);
      if (!ref.is_null()) reference = valueCell(ref) + " <span class=\"muted\">(" + htmlText(h.reference_label) + ")</span>";
    }
    rows.push_back({htmlText(h.label), valueCell(v), htmlText(h.unit), reference});
  }
  rows.push_back({"particle-steps per second", valueCell(r.value("particle_steps_per_s", json())), "1/s", ""});
  rows.push_back({"wall time", valueCell(lookup(r, "wall_time_s.total")), "s", ""});
  std::string s = htmlTable({"figure", "value", "unit", "reference"}, rows);
  s += "<p class=\"muted\">Every figure, with its name in results.json: " + link("results.json", "results.json") + ".</p>\n";
  return htmlSection("Figures", s);
}

/// The chute's markers: DEM truth beside the tracked velocity.
std::string markerTable(const json& r) {
  if (!r.contains("markers") || !r["markers"].is_array() || r["markers"].empty()) return "";
  std::vector<std::vector<std::string>> rows;
  for (const json& m : r["markers"]) {
    if (!m.is_object()) continue;
    rows.push_back({valueCell(m.value("id", json())), valueCell(m.value("column", json())),
                    valueCell(m.value("row", json())), valueCell(m.value("truth_velocity_mps", json())),
                    valueCell(m.value("tracked_velocity_mps", json()))});
  }
  return htmlSection("Markers", htmlTable({"marker", "column", "row", "DEM truth (m/s)", "tracked (m/s)"}, rows));
}

bool isStill(const fs::path& name) { return name.filename().string().find("_still_") != std::string::npos; }

std::string plots(const fs::path& dir) {
  std::string s;
  for (const fs::path& png : filesWithExtension(dir, ".png"))
    if (!isStill(png)) s += htmlFigure(dir, png, png.stem().string());
  return s.empty() ? "" : htmlSection("Plots", s);
}

/// Each camera: its movie (HTML5 video of the MP4; another container is linked)
/// with its first still as poster, and its stills.
std::string movies(const fs::path& dir, const json& r) {
  if (!r.contains("cameras") || !r["cameras"].is_array()) return "";
  std::string s;
  const std::vector<fs::path> stills = filesWithExtension(dir, ".png");
  for (const json& c : r["cameras"]) {
    if (!c.is_object() || !c.contains("name") || !c["name"].is_string()) continue;
    const std::string name = c["name"].get<std::string>();
    std::vector<fs::path> own;
    for (const fs::path& p : stills)
      if (p.string().rfind(name + "_still_", 0) == 0) own.push_back(p);
    s += "<h3>camera " + htmlText(name) + "</h3>\n";
    if (c.contains("movie") && c["movie"].is_string()) {
      const fs::path movie = c["movie"].get<std::string>();
      if (movie.extension() == ".mp4" && fs::exists(dir / movie))
        s += "<video controls=\"controls\" preload=\"metadata\"" +
             (own.empty() ? std::string() : " poster=\"" + hrefOf(own.front()) + "\"") + "><source src=\"" +
             hrefOf(movie) + "\" type=\"video/mp4\" />Your browser cannot play MP4: " + link(movie, movie.string()) +
             "</video>\n";
      s += "<p>Movie: " + link(movie, movie.string()) + " (" + valueCell(c.value("movie_codec", json())) + ", " +
           valueCell(c.value("frames", json())) + " frames at " + valueCell(c.value("frame_rate", json())) +
           " frames/s)</p>\n";
    }
    for (const fs::path& p : own) s += htmlFigure(dir, p, p.stem().string());
  }
  return s.empty() ? "" : htmlSection("Movie and stills", s);
}

std::string timestepAudit(const json& r) {
  static const std::vector<std::pair<const char*, const char*>> kRows = {
      {"critical_s", "critical step (smallest of the limits below)"},
      {"spring_translational_s", "spring, translational √(m/k)"},
      {"spring_rotational_s", "spring, rotational √(I/(k_s R²))"},
      {"rayleigh_s", "Rayleigh wave"},
      {"hertz_contact_time_s", "Hertz contact time"},
      {"linear_contact_time_s", "linear contact time"},
      {"damped_limit_s", "damped limit of one contact mode"},
      {"automatic_s", "automatic step"}};
  if (!r.contains("timestep")) return "";
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"step used, dt", valueCell(r.value("dt_s", json()))});
  for (const auto& [key, label] : kRows) {
    const json v = lookup(r["timestep"], key);
    if (!v.is_null() && !(v.is_number() && v.get<double>() == 0.0)) rows.push_back({htmlText(label), valueCell(v)});
  }
  return htmlSection("Time-step audit", htmlTable({"limit", "seconds"}, rows));
}

std::string stabilityChecks(const json& r) {
  const double ratio = numberAt(r, "timestep.network_step_ratio_max");
  const double over = numberAt(r, "timestep.dt_over_critical");
  std::vector<std::vector<std::string>> rows = {
      {"dt / critical step", shortNumber(over), "the automatic step is timestep.safety_factor (default 0.4) × the critical step"},
      {"contact network: largest dt / stable step", shortNumber(ratio),
       std::isfinite(ratio) && ratio > 1.0 ? "<strong>above 1: unstable</strong>" : "the watchdog stops a run above 1"},
      {"contact network checks", valueCell(lookup(r, "timestep.network_checks")), ""},
      {"warnings", std::to_string(r.value("warnings", json::array()).size()), "listed at the top when any"},
      {"status", valueCell(r.value("status", json())),
       "the watchdog's stop (overlap, energy growth, non-finite state, network) shows here as its reason"}};
  return htmlSection("Stability checks", htmlTable({"check", "value", "meaning"}, rows));
}

std::string wallTime(const json& r) {
  std::vector<std::vector<std::string>> rows;
  const double total = numberAt(r, "wall_time_s.total");
  auto row = [&](const std::string& name, double s) {
    const double share = total > 0 && std::isfinite(s) ? 100.0 * s / total : 0.0;
    const int width = static_cast<int>(std::lround(std::clamp(share, 0.0, 100.0) * 3.0));
    rows.push_back({htmlText(name), shortNumber(s), shortNumber(share),
                    "<span class=\"bar\" style=\"width: " + std::to_string(width) + "px\"></span>"});
  };
  for (const char* part : {"setup", "stepping", "output", "total"})
    row(part, numberAt(r, std::string("wall_time_s.") + part));
  // The stages in the order a step runs them (sim/world.h), not results.json's alphabetical one.
  for (std::size_t k = 0; k < sim::kStageCount; ++k) {
    const std::string stage = sim::stageName(static_cast<sim::Stage>(k));
    row("stepping: " + stage, numberAt(r, "stage_seconds." + stage));
  }
  return htmlSection("Wall time by stage", htmlTable({"part", "seconds", "% of total", ""}, rows));
}

}  // namespace

std::string runReportHtml(const fs::path& dir, const json& r) {
  const std::string scene = r.value("scene", std::string("run"));
  std::string body = "<h1>rocklab run: " + htmlText(scene) + "</h1>\n" + statusLine(r);
  body += whatWasRun(r) + headlineFigures(r) + markerTable(r) + plots(dir) + movies(dir, r) + timestepAudit(r) +
          stabilityChecks(r) + wallTime(r) + htmlSection("Files", htmlFileList(dir));
  return htmlPage("rocklab run: " + scene, body);
}

void writeRunReport(const fs::path& dir, const json& results) {
  writeAtomically(dir / "report.html", runReportHtml(dir, results));
}

int reportCommand(const fs::path& dir, std::ostream& log) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    log << "error: report: " << dir.string() << " is not a folder\n";
    return kExitBadInput;
  }
  if (fs::exists(dir / "results.json", ec)) {
    const json r = readJsonFile(dir / "results.json");
    if (!r.is_object()) {
      log << "error: report: " << (dir / "results.json").string() << " is not a JSON object (damaged or half-written)\n";
      return kExitBadInput;
    }
    writeRunReport(dir, r);
  } else if (isSetFolder(dir)) {
    writeSetReport(dir);
  } else {
    log << "error: report: " << dir.string()
        << " is not a run folder (no results.json) nor a sweep, study or calibration folder (no plan.json, "
           "calibration.csv or runs/)\n";
    return kExitBadInput;
  }
  log << "rocklab: wrote " << (dir / "report.html").string() << "\n";
  return kExitOk;
}

}  // namespace rocklab::experiments::detail
