// Cone crusher run (experiments.md §g.4, §g.6's product): discharge detection
// below the chamber. Every sample_interval the balls whose centre is below
// experiment.discharge_height are product: their id, time, diameter and mass go
// to product.csv, they leave the world (switchPhase with the removal flags: the
// engine keeps a constant model), and results.json gets the product's size
// distribution (mass percent passing each sieve) and its mass balance against
// the feed. Spheres only (the crusher's PBM feed); clumps are refused at the start.
// With [experiment.breakage] the balls break (crusher_breakage.h): the product
// then holds fragments, and results.json's crusher.breakage the events and the
// mass balance (feed = product + what is still in the chamber).
// Beside the sieve curve: P50/P80, throughput and each product ball's residence
// in the chamber (crusher/product_statistics.h), and the mantle's energy and power
// from the work the moving walls do on the balls (World::movingWallWork).
#include "drivers/crusher_experiment.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <ostream>
#include <sstream>

#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "crusher/product_statistics.h"

namespace rocklab::experiments {

namespace {

using crusher::ProductBall;

std::optional<geometry::ConeCrusherGeometry> chamberOf(const Scene& scene) {
  if (!scene.crusher) return std::nullopt;
  return geometry::coneCrusherGeometry(scene.crusher->spec);
}

/// Height (m) of the chamber's top, above which a ball has not entered it: the
/// upper concave's top (the scene's z is the reference's y); +inf without a [crusher].
double chamberTop(const std::optional<geometry::ConeCrusherGeometry>& chamber) {
  return chamber ? chamber->O_top_c.y : std::numeric_limits<double>::infinity();
}

class CrusherRunExperiment final : public Experiment {
 public:
  explicit CrusherRunExperiment(const Scene& scene)
      : e_(settingsOf<CrusherRunSettings>(scene)),
        breakage_(e_.breakage, scene.run.seed),
        chamber_(chamberOf(scene)),
        entries_(chamberTop(chamber_)),
        power_(e_.sample_interval) {}

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) override {
    const sim::ParticleState& p = world->particles();
    if (!started_) {
      started_ = true;
      if (p.clumps.size() > 0)
        throw std::runtime_error("experiment.type = \"crusher\" takes spheres only (the PBM feed); the scene has clumps");
      every_ = stepsIn(e_.sample_interval, world->dt());
      for (std::size_t i = 0; i < p.size(); ++i) feed_.push_back({p.id[i], 0.0, 2 * p.radius[i], p.mass[i], 0.0});
      chamber_mass_ = massOf(feed_);
      if (e_.breakage.enabled) breakage_.start(*world);
    }
    if (world->particles().size() == 0) return false;  // the chamber is empty
    if (e_.breakage.enabled && breakage_.check(world, ctx)) {
      chamber_mass_ = massOf(world->particles());
      const std::vector<BreakageEvent>& events = breakage_.events();
      for (; events_seen_ < events.size(); ++events_seen_)
        entries_.inherit(events[events_seen_].parent, events[events_seen_].fragments);
    }
    if (world->stepCount() % every_ != 0) return true;
    meterPower(*world);
    return discharge(world, ctx);
  }

  /// Removes the balls below discharge_height (product); false when none is left.
  bool discharge(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    const sim::ParticleState& p = world->particles();
    std::vector<double> heights(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) heights[i] = p.position[i].z();
    entries_.record(p.id, heights, world->time());
    std::vector<bool> remove(p.size(), false);
    bool any = false;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!(p.position[i].z() < e_.discharge_height)) continue;
      remove[i] = any = true;
      product_.push_back(
          {p.id[i], world->time(), 2 * p.radius[i], p.mass[i], entries_.residence(p.id[i], world->time())});
    }
    if (any) {
      switchPhase(world, ctx, [](sim::Model&) {}, remove);
      chamber_mass_ = massOf(world->particles());
      if (world->particles().size() == 0) return false;
    }
    return true;
  }

  std::string progress() const override {
    std::ostringstream s;
    s << product_.size() << " balls discharged";
    if (e_.breakage.enabled) s << ", " << breakage_.progress();
    return s.str();
  }

  void report(nlohmann::json& r, const std::filesystem::path& out_dir, std::ostream& log) override {
    const double product_mass = massOf(product_), feed_mass = massOf(feed_);
    const std::vector<double> product_passing = passingOf(product_), feed_passing = passingOf(feed_);
    WhitenInputs whiten;
    whiten.sieves_mm = e_.sieves_mm;
    whiten.feed = &feed_;
    whiten.product = &product_;
    whiten.events = e_.breakage.enabled ? &breakage_.events() : nullptr;
    whiten.mode = e_.breakage.mode;
    if (chamber_) {
      whiten.chamber_css = chamber_->closed_side_gap;
      whiten.chamber_oss = chamber_->open_side_setting;
    }
    std::vector<double> whiten_passing;
    const nlohmann::json whiten_report = whitenReport(e_.whiten, whiten, whiten_passing);
    nlohmann::json psd = nlohmann::json::array(), feed_psd = nlohmann::json::array();
    for (std::size_t k = 0; k < e_.sieves_mm.size(); ++k) {
      psd.push_back({{"size_mm", e_.sieves_mm[k]}, {"passing", product_passing[k]}});
      feed_psd.push_back({{"size_mm", e_.sieves_mm[k]}, {"passing", feed_passing[k]}});
    }
    writeProductCurves(product_passing, feed_passing, whiten_passing, out_dir, log);
    std::ostringstream csv;
    csv.precision(17);
    csv << "id,time_s,diameter_mm,mass_kg,residence_s\n";
    for (const ProductBall& b : product_)
      csv << b.id << ',' << b.time << ',' << b.diameter * 1e3 << ',' << b.mass << ',' << b.residence << '\n';
    detail::writeAtomically(out_dir / "product.csv", csv.str());
    nlohmann::json c;
    c["feed_balls"] = feed_.size();
    c["feed_mass_kg"] = feed_mass;
    c["discharged_balls"] = product_.size();
    c["discharged_mass_kg"] = product_mass;
    c["first_discharge_s"] = product_.empty() ? nlohmann::json(nullptr) : nlohmann::json(product_.front().time);
    c["last_discharge_s"] = product_.empty() ? nlohmann::json(nullptr) : nlohmann::json(product_.back().time);
    c["empty"] = chamber_mass_ == 0;
    c["discharge_height_m"] = e_.discharge_height;
    c["psd"] = psd;
    c["feed_psd"] = feed_psd;
    c["method"] = "a ball whose centre is below discharge_height is product: removed, its diameter and mass recorded "
                  "(product.csv); psd = mass fraction of the product finer than each sieve size";
    c["in_chamber_mass_kg"] = chamber_mass_;
    c.update(crusher::productStatistics(product_));
    c["residence_s"]["method"] = "discharge time minus the time the ball (a fragment: its feed ball) first had its "
                                 "centre below the chamber's top, seen every sample_interval";
    c["throughput_method"] = "discharged mass over the time from the first to the last discharge";
    c["power"] = power_.report();
    c["power_W"] = c["power"]["power_W"];
    c["breakages"] = breakage_.events().size();
    c["whiten"] = whiten_report;
    writePowerPlot(out_dir, log);
    if (e_.breakage.enabled) {
      nlohmann::json b = breakage_.report(e_.sieves_mm, out_dir);
      // Breakage conserves mass to round-off: the feed is the product and what is left.
      b["mass_balance"] = {{"feed_kg", feed_mass},
                           {"product_kg", product_mass},
                           {"in_chamber_kg", chamber_mass_},
                           {"relative_difference", (feed_mass - product_mass - chamber_mass_) / feed_mass}};
      c["breakage"] = b;
    }
    r["crusher"] = c;
    log << "crusher: " << product_.size() << " balls discharged (" << product_mass << " kg of " << feed_mass
        << " kg fed)";
    if (e_.breakage.enabled)
      log << ", " << breakage_.events().size() << " broke into " << breakage_.fragmentsCreated() << " fragments";
    log << "\n";
  }

 private:
  CrusherRunSettings e_;
  bool started_ = false;
  std::uint64_t every_ = 1;
  double chamber_mass_ = 0;  // kg still in the run, updated at every discharge and breakage
  std::vector<ProductBall> product_;
  std::vector<ProductBall> feed_;  // the balls at the start (time 0), for the feed's curve
  CrusherBreakage breakage_;
  std::optional<geometry::ConeCrusherGeometry> chamber_;  // the scene's [crusher], when it has one
  crusher::ChamberEntries entries_;
  crusher::PowerMeter power_;
  double metered_work_ = 0, metered_time_ = 0;  // J, s: the moving walls' work at the last sample
  std::size_t events_seen_ = 0;  // breakage events whose fragments inherited their entry

  static double massOf(const std::vector<ProductBall>& balls) {
    double m = 0;
    for (const ProductBall& b : balls) m += b.mass;
    return m;
  }

  /// Mass fraction of `balls` finer than each sieve (0 for no balls).
  std::vector<double> passingOf(const std::vector<ProductBall>& balls) const {
    return crusher::massPassing(balls, e_.sieves_mm);
  }

  /// product_size.png: cumulative mass percent passing against the sieve size (log
  /// axis, as a sieve chart), the product beside the feed; no product, no curve.
  void writeProductCurves(const std::vector<double>& product, const std::vector<double>& feed,
                          const std::vector<double>& whiten, const std::filesystem::path& out_dir,
                          std::ostream& log) const {
    PlotSpec spec = sieveChart("Product size distribution (" + std::to_string(product_.size()) + " balls discharged)");
    PlotSeries f{"feed", e_.sieves_mm, {}, PlotSeries::Style::LinePoints};
    PlotSeries p{"product", product_.empty() ? std::vector<double>{} : e_.sieves_mm, {}, PlotSeries::Style::LinePoints};
    for (const double v : feed) f.y.push_back(100 * v);
    if (!product_.empty())
      for (const double v : product) p.y.push_back(100 * v);
    spec.series = {p, f};
    if (!whiten.empty()) {  // Whiten's model from parameters, for the same feed (crusher_whiten.h)
      PlotSeries w{"Whiten's model (k1 = CSS, k2 = OSS)", e_.sieves_mm, {}, PlotSeries::Style::LinePoints};
      for (const double v : whiten) w.y.push_back(100 * v);
      spec.series.push_back(w);
    }
    try {
      writePlot(spec, out_dir / "product_size.png");
    } catch (const std::exception& e) {
      log << "crusher: no product curve (" << e.what() << ")\n";
    }
  }

  /// The moving walls' work since the last sample, as the power of that interval.
  /// World::movingWallWork goes on through the World's rebuilds (discharge, breakage).
  void meterPower(const sim::World& world) {
    const double work = world.movingWallWork(), span = world.time() - metered_time_;
    if (span > 0) power_.add(metered_time_, (work - metered_work_) / span, span);
    metered_work_ = work;
    metered_time_ = world.time();
  }

  /// mantle_power.png: the moving walls' power, averaged over each sample_interval.
  void writePowerPlot(const std::filesystem::path& out_dir, std::ostream& log) const {
    if (power_.series().empty()) return;
    PlotSpec spec;
    spec.title = "Mantle power (work of the moving walls on the balls)";
    spec.x_label = "time (s)";
    spec.y_label = "power (W)";
    PlotSeries series{"mantle and cap", {}, {}, PlotSeries::Style::Line};
    for (const auto& [t, w] : power_.series()) {
      series.x.push_back(t);
      series.y.push_back(w);
    }
    spec.series = {series};
    try {
      writePlot(spec, out_dir / "mantle_power.png");
    } catch (const std::exception& e) {
      log << "crusher: no power plot (" << e.what() << ")\n";
    }
  }

  static double massOf(const sim::ParticleState& p) {
    double m = 0;
    for (const double b : p.mass) m += b;
    return m;
  }
};

}  // namespace

std::unique_ptr<Experiment> makeCrusherRunExperiment(const Scene& scene) {
  return std::make_unique<CrusherRunExperiment>(scene);
}

std::shared_ptr<ExperimentSettings> readCrusherRunSettings(TableReader& t, const SettingsContext&) {
  auto settings = std::make_shared<CrusherRunSettings>();
  settings->discharge_height = t.number("discharge_height", settings->discharge_height);
  if (t.has("sieves_mm")) {
    settings->sieves_mm = t.numberList("sieves_mm", Range::positive());
    if (!std::is_sorted(settings->sieves_mm.begin(), settings->sieves_mm.end()) || settings->sieves_mm.empty())
      t.fail("sieves_mm", "must be a non-empty list of sizes in increasing order (mm)");
  }
  readBreakageSettings(t, settings->breakage);
  settings->whiten.k1 = 1e-3 * t.number("whiten_k1_mm", 0.0, Range::nonNegative());
  settings->whiten.k2 = 1e-3 * t.number("whiten_k2_mm", 0.0, Range::nonNegative());
  settings->whiten.exponent = t.number("whiten_exponent", settings->whiten.exponent, Range::positive());
  if (settings->whiten.k1 > 0 && settings->whiten.k2 > 0 && !(settings->whiten.k1 < settings->whiten.k2))
    t.fail("whiten_k2_mm", "must be larger than whiten_k1_mm (Eq 3-22 needs k1 < k2)");
  return settings;
}

}  // namespace rocklab::experiments
