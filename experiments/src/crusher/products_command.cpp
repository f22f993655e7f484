#include "crusher/products_command.h"

#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/run_comparison.h"
#include "crusher/psd_curve.h"
#include "rocklab/experiments/run.h"
#include "sets/run_set.h"

namespace rocklab::experiments {

namespace {

struct ProductRun {
  std::string label;
  std::filesystem::path dir;
  std::vector<double> sieves, passing, feed_passing;  // mm; fractions
  nlohmann::json figures;                             // the table's row
};

/// The number of `c` at `key`, null when it is missing or not a number (a run with no product).
nlohmann::json numberOrNull(const nlohmann::json& c, const char* key) {
  return c.contains(key) && c[key].is_number() ? c[key] : nlohmann::json(nullptr);
}

ProductRun readRun(const std::filesystem::path& dir) {
  const nlohmann::json r = crusher::readCrusherResults(dir);
  const nlohmann::json& c = r.at("crusher");
  ProductRun run;
  run.dir = dir;
  std::vector<double> feed_sieves;
  crusher::readSieveCurve(crusher::needKey(c, "psd", "crusher"), "crusher.psd", run.sieves,
                          run.passing);
  crusher::readSieveCurve(crusher::needKey(c, "feed_psd", "crusher"), "crusher.feed_psd",
                          feed_sieves, run.feed_passing);
  if (feed_sieves != run.sieves)
    throw crusher::PsdInputError("crusher.psd: its sizes differ from crusher.feed_psd's");
  const nlohmann::json wall = r.value("wall_time_s", nlohmann::json());
  // A bonded feed breaks by its bonds (its breakages count replacements, none).
  nlohmann::json bonds_broken;
  if (c.contains("bonded")) {
    const nlohmann::json& b = c["bonded"];
    const nlohmann::json all = numberOrNull(b, "bonds"),
                         intact = numberOrNull(b, "bonds_intact_at_end");
    if (!all.is_null() && !intact.is_null()) bonds_broken = all.get<long>() - intact.get<long>();
  }
  // How much of the feed the product is: 1 for a run to an empty chamber, less for
  // one stopped before (its curve is what had come out by then).
  const nlohmann::json discharged = numberOrNull(c, "discharged_mass_kg"),
                       fed = numberOrNull(c, "feed_mass_kg");
  const nlohmann::json discharged_fraction =
      !discharged.is_null() && !fed.is_null() && fed.get<double>() > 0
          ? nlohmann::json(discharged.get<double>() / fed.get<double>())
          : nlohmann::json(nullptr);
  run.figures = {
      {"scene", r.value("scene", "")},
      {"feed", c.contains("bonded") ? "bonded agglomerates (Eq 6-15 sizes)" : "spheres"},
      {"feed_particles", c.value("feed_balls", nlohmann::json())},
      {"breakages", c.value("breakages", nlohmann::json())},
      {"bonds_broken", bonds_broken},
      {"discharged_fraction", discharged_fraction},
      {"p50_mm", numberOrNull(c, "p50_mm")},
      {"p80_mm", numberOrNull(c, "p80_mm")},
      {"throughput_tph", numberOrNull(c, "throughput_tph")},
      {"power_W", numberOrNull(c, "power_W")},
      {"chamber_empty", c.value("empty", nlohmann::json())},
      {"simulated_time_s", r.value("simulated_time_s", nlohmann::json())},
      {"wall_time_s", wall.is_object() ? wall.value("total", nlohmann::json()) : nlohmann::json()}};
  return run;
}

/// The run's label in the chart; a run stopped before its chamber emptied says how
/// much of its feed its curve holds and by when.
std::string legendOf(const ProductRun& run) {
  const nlohmann::json& f = run.figures;
  if (f["chamber_empty"] != false || !f["discharged_fraction"].is_number()) return run.label;
  std::ostringstream s;
  s << run.label << " (not empty: " << std::fixed << std::setprecision(0)
    << 100 * f["discharged_fraction"].get<double>() << " % of the feed";
  if (f["simulated_time_s"].is_number())
    s << " by t = " << std::setprecision(2) << f["simulated_time_s"].get<double>() << " s";
  s << ")";
  return s.str();
}

}  // namespace

int runProductsCommand(const RunComparisonOptions& o, std::ostream& out, std::ostream& err) {
  if (const std::string problem = detail::runLabelsProblem(o.runs.size(), o.labels.size());
      !problem.empty()) {
    err << "error: products: " << problem << "\n";
    return kExitBadInput;
  }
  std::vector<ProductRun> runs;
  for (std::size_t k = 0; k < o.runs.size(); ++k) {
    const std::filesystem::path file = o.runs[k] / "results.json";
    try {
      runs.push_back(readRun(o.runs[k]));
    } catch (const crusher::PsdInputError& e) {
      err << "error: " << file.string() << ": " << e.what() << '\n';
      return kExitBadInput;
    }
    runs.back().label = detail::runLabel(o.runs, o.labels, k);
    if (runs.back().sieves != runs.front().sieves) {
      err << "error: " << file.string() << ": crusher.psd: its sieves differ from those of "
          << (o.runs.front() / "results.json").string() << " (allowed: runs on the same sieves)\n";
      return kExitBadInput;
    }
  }
  const std::vector<double>& sieves = runs.front().sieves;

  // The table: figures, then the product's passing at each sieve.
  std::ostringstream csv;
  csv << "label,run";
  const std::vector<std::string> columns{"scene",
                                         "feed",
                                         "feed_particles",
                                         "breakages",
                                         "bonds_broken",
                                         "p50_mm",
                                         "p80_mm",
                                         "throughput_tph",
                                         "power_W",
                                         "chamber_empty",
                                         "discharged_fraction",
                                         "simulated_time_s",
                                         "wall_time_s"};
  for (const std::string& c : columns) csv << ',' << c;
  for (const double s : sieves) csv << ",passing_" << s << "mm";
  csv << '\n';
  nlohmann::json table = nlohmann::json::array();
  for (const ProductRun& run : runs) {
    csv << detail::csvCell(run.label) << ',' << detail::csvCell(run.dir.string());
    for (const std::string& c : columns)
      csv << ',' << detail::csvCell(detail::cell(run.figures[c]));
    nlohmann::json row = run.figures;
    row["label"] = run.label;
    row["legend"] = legendOf(run);
    row["run"] = run.dir.string();
    nlohmann::json psd = nlohmann::json::array(), feed = nlohmann::json::array();
    for (std::size_t k = 0; k < sieves.size(); ++k) {
      csv << ',' << run.passing[k];
      psd.push_back({{"size_mm", sieves[k]}, {"passing", run.passing[k]}});
      feed.push_back({{"size_mm", sieves[k]}, {"passing", run.feed_passing[k]}});
    }
    csv << '\n';
    row["psd"] = psd;
    row["feed_psd"] = feed;
    table.push_back(row);
  }

  // The chart: each run's product (points and line) and its feed (line) in one
  // colour; one feed curve when every run had the same feed.
  PlotSpec spec = sieveChart("product size distribution of each run");
  bool one_feed = true;
  for (const ProductRun& run : runs)
    one_feed = one_feed && run.feed_passing == runs.front().feed_passing;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    PlotSeries product{legendOf(runs[k]), sieves, {}, PlotSeries::Style::LinePoints};
    for (const double p : runs[k].passing) product.y.push_back(100 * p);
    product.colour = static_cast<int>(k);
    spec.series.push_back(product);
  }
  for (std::size_t k = 0; k < (one_feed ? 1 : runs.size()); ++k) {
    PlotSeries feed{
        one_feed ? "feed" : "feed: " + runs[k].label, sieves, {}, PlotSeries::Style::Line};
    for (const double p : runs[k].feed_passing) feed.y.push_back(100 * p);
    feed.colour = one_feed ? static_cast<int>(runs.size()) : static_cast<int>(k);
    spec.series.push_back(feed);
  }
  try {
    std::filesystem::create_directories(o.out_dir);
    detail::writeAtomically(o.out_dir / "products.csv", csv.str());
    detail::writeAtomically(o.out_dir / "products.json",
                            nlohmann::json({{"runs", table}}).dump(2) + "\n");
    writePlot(spec, o.out_dir / "product_curves.png");
  } catch (const std::exception& e) {
    err << "error: products: " << e.what() << '\n';
    return kExitFailed;
  }
  // The console table: one space at least between columns, whatever a cell's width.
  struct ConsoleColumn {
    const char* header;
    int width;
    const char* figure;  // key of ProductRun::figures
    double scale;        // shown as scale x the figure
  };
  static constexpr ConsoleColumn kConsole[] = {
      {"P50_mm", 9, "p50_mm", 1},       {"P80_mm", 9, "p80_mm", 1},
      {"breakages", 9, "breakages", 1}, {"bonds_broken", 12, "bonds_broken", 1},
      {"t/h", 9, "throughput_tph", 1},  {"empty", 5, "chamber_empty", 1},
      {"discharged_%", 12, "discharged_fraction", 100}};
  out << std::left << std::setw(28) << "run" << std::right;
  for (const ConsoleColumn& c : kConsole) out << ' ' << std::setw(c.width) << c.header;
  out << '\n';
  for (const ProductRun& run : runs) {
    out << std::left << std::setw(28) << run.label << std::right;
    for (const ConsoleColumn& c : kConsole) {
      const nlohmann::json& v = run.figures[c.figure];
      out << ' ' << std::setw(c.width)
          << detail::cell(v.is_number() ? nlohmann::json(c.scale * v.get<double>()) : v);
    }
    out << '\n';
  }
  out << "wrote " << (o.out_dir / "products.csv").string()
      << ", products.json and product_curves.png\n";
  return 0;
}

}  // namespace rocklab::experiments
