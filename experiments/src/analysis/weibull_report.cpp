#include "analysis/weibull_report.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "analysis/batch_curves.h"
#include "analysis/plot.h"
#include "analysis/sweep_table.h"
#include "analysis/weibull.h"
#include "common/atomic_file.h"
#include "common/json_text.h"
#include "rocklab/experiments/run.h"  // exit codes

namespace rocklab::experiments {

int weibullCommand(const std::filesystem::path& dir, const std::string& column, std::ostream& log) {
  const std::filesystem::path csv = dir / "sweep.csv";
  std::vector<double> strengths;
  std::size_t skipped = 0;
  try {
    const SweepTable table = readSweepTable(dir);
    const std::size_t col = table.column(column);
    skipped = table.not_ok;
    for (const auto& row : table.rows) {
      const auto v = SweepTable::numberIn(row, col);
      if (v && *v > 0)
        strengths.push_back(*v);
      else
        ++skipped;
    }
  } catch (const std::invalid_argument& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  WeibullFit fit;
  try {
    fit = fitWeibull(strengths);
  } catch (const std::invalid_argument& e) {
    log << "error: " << csv.string() << ": " << e.what() << " (" << skipped
        << " rows without a value)\n";
    return kExitBadInput;
  }
  nlohmann::json j;
  j["column"] = column;
  j["count"] = fit.count;
  j["skipped_rows"] = skipped;
  j["weibull_m"] = fit.modulus;
  j["weibull_sigma0_MPa"] = fit.sigma0;
  j["weibull_r2"] = fit.r2;
  j["mean_MPa"] = fit.mean;
  j["stddev_MPa"] = fit.stddev;
  j["cov"] = fit.cov;
  j["method"] =
      "mean rank P_s = 1 - i/(N+1) (Eq 5-2), least squares of ln ln(1/P_s) on ln sigma (Eq 5-4)";
  j["strengths_MPa"] = fit.sorted;
  detail::writeAtomically(dir / "weibull.json", detail::jsonText(j));
  PlotSeries points{"runs", {}, {}, PlotSeries::Style::Points};
  for (std::size_t i = 0; i < fit.count; ++i) {
    points.x.push_back(std::log(fit.sorted[i]));
    points.y.push_back(std::log(std::log(1.0 / fit.survival[i])));
  }
  std::ostringstream label;
  label.precision(3);
  label << "fit: m = " << fit.modulus << ", sigma0 = " << fit.sigma0 << " MPa, R^2 = " << fit.r2;
  PlotSeries line_fit{label.str(), {}, {}, PlotSeries::Style::Line};
  for (const double x : {points.x.front(), points.x.back()}) {
    line_fit.x.push_back(x);
    line_fit.y.push_back(fit.modulus * (x - std::log(fit.sigma0)));
  }
  PlotSpec spec;
  spec.title = "Weibull plot of " + std::to_string(fit.count) + " crushing tests (Eq 5-4)";
  spec.x_label = "ln(strength / 1 MPa)";
  spec.y_label = "ln ln(1 / P_s)";
  spec.series = {points, line_fit};
  writePlot(spec, dir / "weibull.png");
  log << "weibull: " << fit.count << " strengths: m = " << fit.modulus
      << ", sigma0 = " << fit.sigma0 << " MPa, R^2 = " << fit.r2 << ", mean " << fit.mean
      << " MPa, CoV " << fit.cov << "; " << (dir / "weibull.json").string() << ", "
      << (dir / "weibull.png").string() << "\n";
  writeBatchForceCurves(dir, "", log);
  return kExitOk;
}

}  // namespace rocklab::experiments
