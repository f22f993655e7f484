// The crusher's parameter studies (experiments.md §g.9) as sweeps: each run's
// product curve on one sieve chart beside the table of the product figures.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.h"
#include "crusher_support.h"

namespace fs = std::filesystem;
using namespace rocklab::experiments;

namespace {

/// product_curves.plot.csv as series → the y values in order.
std::map<std::string, std::vector<double>> plottedCurves(const fs::path& csv) {
  std::map<std::string, std::vector<double>> curves;
  std::istringstream in(test::slurp(csv));
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    // series names hold ", " and are quoted; x and y are the last two cells
    const auto last = line.rfind(','), before = line.rfind(',', last - 1);
    std::string name = line.substr(0, before);
    if (name.size() >= 2 && name.front() == '"') name = name.substr(1, name.size() - 2);
    curves[name].push_back(std::stod(line.substr(last + 1)));
  }
  return curves;
}

}  // namespace

TEST_CASE("a crusher sweep tabulates each run's product figures and draws every product curve beside the feed",
          "[cli][crusher][sweep]") {
  // The tiny crusher run with breakage (crusher_support.h; the settings of the tiny
  // breakage run) at two strengths: 0.2 MPa breaks the feed, 2 GPa breaks nothing.
  const fs::path out = test::scratchDir("crusher-sweep");
  const std::vector<std::string> run = test::tinyCrusherRunArgs((out / "unused").string());
  std::vector<std::string> args{"sweep", run[1], "--out", out.string(), "--jobs", "0", "--threads", "1", "--quiet",
                                "--vary", "experiment.breakage.q_ref=2e5,2e9"};
  args.insert(args.end(), run.begin() + 7, run.end());  // its --set pairs
  for (const char* set : {"experiment.breakage.check_interval=2e-5", "experiment.breakage.youngs_modulus=1e8",
                          "experiment.breakage.min_diameter=0.0079", "timestep.dt=7e-7", "output.vtk=false"})
    args.insert(args.end(), {"--set", set});
  REQUIRE(test::cli(args) == 0);

  // The table: the product figures by default, one row a run.
  const std::string table = test::slurp(out / "sweep.csv");
  CHECK(table.rfind("experiment.breakage.q_ref,crusher.p50_mm,crusher.p80_mm,crusher.throughput_tph,crusher.power_W,"
                    "crusher.breakages,crusher.empty",
                    0) == 0);
  std::vector<nlohmann::json> results;
  for (const char* dir : {"experiment.breakage.q_ref=2e5", "experiment.breakage.q_ref=2e9"}) {
    std::ifstream in(out / "runs" / dir / "results.json");
    results.push_back(nlohmann::json::parse(in));
  }
  REQUIRE(results[0]["crusher"]["breakages"].get<int>() >= 1);
  REQUIRE(results[1]["crusher"]["breakages"] == 0);

  // The chart: the feed and one curve a run, each the run's own cumulative passing.
  REQUIRE(fs::exists(out / "product_curves.png"));
  const auto curves = plottedCurves(out / "product_curves.plot.csv");
  REQUIRE(curves.size() == 3);
  const std::vector<std::string> labels{"experiment.breakage.q_ref = 2e5", "experiment.breakage.q_ref = 2e9"};
  for (std::size_t k = 0; k < 2; ++k) {
    INFO(labels[k]);
    REQUIRE(curves.count(labels[k]) == 1);
    const auto& psd = results[k]["crusher"]["psd"];
    const std::vector<double>& y = curves.at(labels[k]);
    REQUIRE(y.size() == psd.size());
    for (std::size_t s = 0; s < y.size(); ++s) CHECK(y[s] == Approx(100 * psd[s]["passing"].get<double>()).margin(1e-6));
  }
  // What breakage does, as the chart shows it: the strong feed's product is the
  // feed, the weak feed's is finer on some sieve and coarser on none.
  const std::vector<double>& feed = curves.at("feed");
  const std::vector<double>& weak = curves.at(labels[0]);
  const std::vector<double>& strong = curves.at(labels[1]);
  bool finer = false;
  for (std::size_t s = 0; s < feed.size(); ++s) {
    CHECK(strong[s] == Approx(feed[s]).margin(1e-9));
    CHECK(weak[s] >= feed[s] - 1e-9);
    finer = finer || weak[s] > feed[s] + 1e-6;
  }
  CHECK(finer);
  // The set's page shows the chart.
  CHECK(test::slurp(out / "report.html").find("product_curves.png") != std::string::npos);
}
