#include "crusher/whiten_command.h"

#include <iomanip>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "crusher/breakage_model.h"
#include "crusher/psd_curve.h"
#include "crusher/whiten_model.h"
#include "drivers/crusher_whiten.h"
#include "rocklab/experiments/run.h"

namespace rocklab::experiments {

int runWhitenCommand(const WhitenCommandOptions& o, std::ostream& out, std::ostream& err) {
  const std::filesystem::path file = o.run_dir / "results.json";
  try {
    const nlohmann::json r = crusher::readCrusherResults(o.run_dir);
    const nlohmann::json& c = r.at("crusher");
    std::vector<double> sieves, feed_passing, sizes, product_passing;
    crusher::readSieveCurve(crusher::needKey(c, "feed_psd", "crusher"), "crusher.feed_psd", sieves, feed_passing);
    crusher::readSieveCurve(crusher::needKey(c, "psd", "crusher"), "crusher.psd", sizes, product_passing);
    if (sizes != sieves) throw crusher::PsdInputError("crusher.psd: its sizes differ from crusher.feed_psd's");
    const nlohmann::json& mass_j = crusher::needKey(c, "feed_mass_kg", "crusher");
    if (!mass_j.is_number() || !(mass_j.get<double>() > 0)) throw crusher::PsdInputError("crusher.feed_mass_kg: must be > 0");
    const double feed_mass = mass_j.get<double>();
    // Mass per class, coarse to fine (crusher::SizeClasses): the top class above the
    // largest sieve, the pan below the smallest.
    const std::size_t n = sieves.size();
    Eigen::VectorXd feed(static_cast<Eigen::Index>(n + 1));
    feed[0] = (1 - feed_passing[n - 1]) * feed_mass;
    for (std::size_t k = 1; k < n; ++k)
      feed[static_cast<Eigen::Index>(k)] = (feed_passing[n - k] - feed_passing[n - 1 - k]) * feed_mass;
    feed[static_cast<Eigen::Index>(n)] = feed_passing[0] * feed_mass;
    if ((feed.array() < -1e-12 * feed_mass).any()) throw crusher::PsdInputError("crusher.feed_psd: passing must not decrease");
    feed = feed.cwiseMax(0.0);

    // The run's own settings unless asked otherwise.
    const nlohmann::json run_params =
        c.contains("whiten") && c["whiten"].contains("from_parameters") ? c["whiten"]["from_parameters"] : nlohmann::json();
    auto runValue = [&](const char* key) -> std::optional<double> {
      if (run_params.contains(key) && run_params[key].is_number()) return run_params[key].get<double>();
      return std::nullopt;
    };
    const std::optional<double> k1 = o.k1_mm ? o.k1_mm : runValue("k1_mm");
    const std::optional<double> k2 = o.k2_mm ? o.k2_mm : runValue("k2_mm");
    if (!k1 || !k2)
      throw crusher::PsdInputError("crusher.whiten.from_parameters has no k1_mm / k2_mm (a run without a [crusher] chamber): give "
                     "--k1-mm and --k2-mm");
    if (!(*k1 > 0 && *k1 < *k2))
      throw crusher::PsdInputError("--k1-mm / --k2-mm: need 0 < k1 < k2, got " + std::to_string(*k1) + " and " + std::to_string(*k2));
    if (!(o.exponent > 0)) throw crusher::PsdInputError("--exponent: must be > 0");
    std::string mode = o.mode;
    if (mode.empty()) mode = run_params.contains("split") && run_params["split"].is_string() ? run_params["split"].get<std::string>() : "triple";
    if (mode != "triple" && mode != "equal") throw crusher::PsdInputError("--mode: must be triple or equal, got '" + mode + "'");
    const crusher::SplitMode split = mode == "equal" ? crusher::SplitMode::Equal : crusher::SplitMode::Triple;

    const WhitenPrediction w = whitenFromParameters(sieves, feed, *k1 * 1e-3, *k2 * 1e-3, o.exponent, split);
    out << "Whiten's model (Eq 3-20) on the feed of " << file.string() << ": k1 = " << *k1 << " mm, k2 = " << *k2
        << " mm, exponent " << o.exponent << ", " << mode << " split\n";
    out << std::setw(10) << "sieve_mm" << std::setw(10) << "feed_%" << std::setw(12) << "DEM_%" << std::setw(12)
        << "Whiten_%\n";
    nlohmann::json curve = nlohmann::json::array();
    for (std::size_t k = 0; k < n; ++k) {
      out << std::fixed << std::setprecision(2) << std::setw(10) << sieves[k] << std::setw(10) << 100 * feed_passing[k]
          << std::setw(12) << 100 * product_passing[k] << std::setw(12) << 100 * w.passing[k] << '\n';
      curve.push_back({{"size_mm", sieves[k]}, {"passing", w.passing[k]}});
    }
    out << std::defaultfloat << "mass balance (product - feed) / feed: " << w.mass_balance_relative << '\n';
    const nlohmann::json result = {{"run", o.run_dir.string()},
                                   {"k1_mm", *k1},
                                   {"k2_mm", *k2},
                                   {"exponent", o.exponent},
                                   {"split", mode},
                                   {"selection", w.selection},
                                   {"passing", curve},
                                   {"mass_balance_relative", w.mass_balance_relative}};
    const std::filesystem::path dir = o.out_dir.empty() ? o.run_dir : o.out_dir;
    std::filesystem::create_directories(dir);
    detail::writeAtomically(dir / "whiten.json", result.dump(2) + "\n");
    PlotSpec spec = sieveChart("Whiten's model against the DEM product");
    PlotSeries dem{"DEM product", sieves, {}, PlotSeries::Style::LinePoints};
    PlotSeries model{"Whiten (k1 " + std::to_string(*k1).substr(0, 5) + ", k2 " + std::to_string(*k2).substr(0, 5) + " mm)",
                     sieves, {}, PlotSeries::Style::LinePoints};
    PlotSeries f{"feed", sieves, {}, PlotSeries::Style::LinePoints};
    for (std::size_t k = 0; k < n; ++k) {
      dem.y.push_back(100 * product_passing[k]);
      model.y.push_back(100 * w.passing[k]);
      f.y.push_back(100 * feed_passing[k]);
    }
    spec.series = {dem, model, f};
    writePlot(spec, dir / "whiten.png");
    out << "wrote " << (dir / "whiten.json").string() << " and whiten.png\n";
    return 0;
  } catch (const crusher::PsdInputError& e) {
    err << "error: " << file.string() << ": " << e.what() << '\n';
    return kExitBadInput;
  } catch (const crusher::WhitenInputError& e) {
    err << "error: " << file.string() << ": " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "error: whiten: " << e.what() << '\n';
    return kExitBadInput;
  }
}

}  // namespace rocklab::experiments
