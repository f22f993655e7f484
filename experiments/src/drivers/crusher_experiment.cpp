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
#include <unordered_map>

#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "crusher/product_statistics.h"
#include "rocklab/sim/bonds.h"

namespace rocklab::experiments {

namespace {

using crusher::ProductBall;

constexpr const char* kStopWall = "crusher.stop";  // §g.4's flat wall under the feed bin

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
        power_(e_.sample_interval),
        agglomerates_(scene.agglomerates) {
    for (const sim::Wall& w : scene.model.walls)
      if (w.name == kStopWall) release_time_ = w.active_until;
  }

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) override {
    const sim::ParticleState& p = world->particles();
    if (!started_) {
      started_ = true;
      if (p.clumps.size() > 0)
        throw std::runtime_error("experiment.type = \"crusher\" takes spheres only (the PBM feed); the scene has clumps");
      every_ = stepsIn(e_.sample_interval, world->dt());
      bonded_ = world->bonds().size() > 0;
      bonds_at_start_ = bonds_intact_ = world->bonds().size();
      if (bonded_ && e_.breakage.enabled)
        throw std::runtime_error("experiment.breakage (the population balance) and a bonded feed exclude each other: "
                                 "agglomerates break by their bonds (§g.7)");
      startFeed(p);
      chamber_mass_ = massOf(feed_);
      if (e_.breakage.enabled) breakage_.start(*world);
      if (bonded_ && e_.settle_bond_factor != 1.0) strengthenBonds(world, ctx);
    }
    if (strengthened_ && world->time() >= release_time_) restoreBonds(world, ctx);
    if (world->particles().size() == 0) return false;  // the chamber is empty
    if (e_.breakage.enabled && world->time() >= breakageStart() && breakage_.check(world, ctx)) {
      chamber_mass_ = massOf(world->particles());
      const std::vector<BreakageEvent>& events = breakage_.events();
      for (; events_seen_ < events.size(); ++events_seen_)
        entries_.inherit(events[events_seen_].parent, events[events_seen_].fragments);
    }
    // A stop request cut the freeze short: no discharge either, so that a restart
    // redoes this step's check and discharge in their order (advanceUndone).
    if (breakage_.interrupted()) return true;
    if (world->stepCount() % every_ != 0) return true;
    meterPower(*world);
    ball_count_.emplace_back(world->time(), static_cast<double>(world->particles().size()));
    if (bonded_) {
      const auto& intact = world->bonds().intact;
      bonds_intact_ = static_cast<std::size_t>(std::count(intact.begin(), intact.end(), std::uint8_t{1}));
    }
    return discharge(world, ctx);
  }

  /// Removes the balls below discharge_height (product; a bonded feed: the
  /// fragments whose centre of mass is below it); false when none is left.
  bool discharge(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    const sim::ParticleState& p = world->particles();
    std::vector<double> heights(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) heights[i] = p.position[i].z();
    entries_.record(p.id, heights, world->time());
    std::vector<bool> remove(p.size(), false);
    bool any = false;
    if (bonded_) {
      any = dischargeFragments(*world, remove);
    } else {
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (!(p.position[i].z() < e_.discharge_height)) continue;
        remove[i] = any = true;
        product_.push_back(
            {p.id[i], world->time(), 2 * p.radius[i], p.mass[i], entries_.residence(p.id[i], world->time())});
      }
    }
    if (any) {
      switchPhase(world, ctx, [](sim::Model&) {}, remove);
      chamber_mass_ = massOf(world->particles());
      if (world->particles().size() == 0) return false;
    }
    return true;
  }

  /// The fragments (balls joined by intact bonds) whose centre of mass is below
  /// discharge_height: recorded as product (Eq 6-15 size) and flagged in `remove`.
  bool dischargeFragments(const sim::World& world, std::vector<bool>& remove) {
    const sim::ParticleState& p = world.particles();
    const std::vector<std::uint32_t> label = sim::bondedClusters(p.size(), world.bonds());
    const std::size_t n = label.empty() ? 0 : *std::max_element(label.begin(), label.end()) + 1;
    std::vector<double> mass(n, 0.0), moment(n, 0.0), volume(n, 0.0);
    std::vector<std::size_t> first(n, p.size()), balls(n, 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const std::uint32_t f = label[i];
      mass[f] += p.mass[i];
      moment[f] += p.mass[i] * p.position[i].z();
      volume[f] += 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius[i], 3);
      first[f] = std::min(first[f], i);
      ++balls[f];
    }
    std::vector<bool> out(n, false);
    bool any = false;
    // Centre of mass below: `out`; residence from its earliest ball's entry.
    for (std::size_t f = 0; f < n; ++f) {
      out[f] = moment[f] < e_.discharge_height * mass[f];
      any = any || out[f];
    }
    std::vector<double> residence(n, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!out[label[k]]) continue;
      const double r = entries_.residence(p.id[k], world.time());
      double& best = residence[label[k]];
      if (std::isnan(best) || r > best) best = r;
    }
    for (std::size_t f = 0; f < n; ++f) {
      if (!out[f]) continue;
      const std::size_t i = first[f];
      const double porosity = porosityOf(p.id[i]);
      // Eq 6-15; a lone ball of no agglomerate is its own size, exactly.
      const double diameter = balls[f] == 1 && porosity == 0.0
                                  ? 2 * p.radius[i]
                                  : 2 * std::cbrt(3 * volume[f] / (4 * std::numbers::pi * (1 - porosity)));
      product_.push_back({p.id[i], world.time(), diameter, mass[f], residence[f]});
      fragment_balls_.push_back(balls[f]);
    }
    for (std::size_t i = 0; i < p.size(); ++i) remove[i] = out[label[i]];
    return any;
  }

  /// The feed's curve: one entry per agglomerate (Eq 6-15 of the whole: its
  /// diameter) and per ball of none.
  void startFeed(const sim::ParticleState& p) {
    std::vector<bool> in_agglomerate(p.size(), false);
    for (const AgglomerateReport& a : agglomerates_) {
      double mass = 0;
      for (std::size_t i = a.first_ball; i < a.first_ball + a.balls && i < p.size(); ++i) {
        mass += p.mass[i];
        in_agglomerate[i] = true;
        porosity_[p.id[i]] = a.porosity;
      }
      const double diameter = 2 * std::cbrt(3 * a.solid_volume / (4 * std::numbers::pi * (1 - a.porosity)));
      feed_.push_back({a.balls > 0 ? p.id[a.first_ball] : 0, 0.0, diameter, mass, 0.0});
    }
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!in_agglomerate[i]) feed_.push_back({p.id[i], 0.0, 2 * p.radius[i], p.mass[i], 0.0});
  }

  double porosityOf(std::uint64_t id) const {
    const auto it = porosity_.find(id);
    return it == porosity_.end() ? 0.0 : it->second;
  }

  /// The bonds' strengths times settle_bond_factor while the feed settles (§g.7 step 3).
  void strengthenBonds(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    switchState(world, ctx, [&](sim::WorldState& s) {
      tensile_ = s.bonds.tensile_strength;
      shear_ = s.bonds.shear_strength;
      for (double& v : s.bonds.tensile_strength) v *= e_.settle_bond_factor;
      for (double& v : s.bonds.shear_strength) v *= e_.settle_bond_factor;
    });
    strengthened_ = true;
  }

  /// Step 4: the strengths as they were (bit for bit when no bond left meanwhile).
  void restoreBonds(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    switchState(world, ctx, [&](sim::WorldState& s) {
      intact_at_release_ = static_cast<double>(std::count(s.bonds.intact.begin(), s.bonds.intact.end(), std::uint8_t{1}));
      if (s.bonds.size() == tensile_.size()) {
        s.bonds.tensile_strength = tensile_;
        s.bonds.shear_strength = shear_;
      } else {
        for (double& v : s.bonds.tensile_strength) v /= e_.settle_bond_factor;
        for (double& v : s.bonds.shear_strength) v /= e_.settle_bond_factor;
      }
    });
    strengthened_ = false;
    restored_at_ = world->time();
  }

  bool restartable() const override { return true; }
  // What came before the check in advance() is done once (the strengths given back)
  // or the same when done again (the kinetic-energy watch).
  bool advanceUndone() const override { return breakage_.interrupted(); }

  nlohmann::json saveState() const override {
    nlohmann::json j;
    savedFields(*this, [&j](const char* key, const auto& value) { j[key] = value; });
    j["ball_count"] = ball_count_;
    j["breakage"] = e_.breakage.enabled ? breakage_.saveState() : nlohmann::json(nullptr);
    return j;
  }

  void restoreState(const nlohmann::json& j, sim::Model& model) override {
    savedFields(*this, [&j](const char* key, auto& value) { j.at(key).get_to(value); });
    // Not in the checkpoints of 3242d50 and e87d732: their series starts at the restart.
    ball_count_.clear();
    if (j.contains("ball_count")) j.at("ball_count").get_to(ball_count_);
    if (const nlohmann::json& b = j.at("breakage"); b.is_null() == e_.breakage.enabled)
      throw std::invalid_argument(std::string("the run was saved ") + (b.is_null() ? "without" : "with") +
                                  " [experiment.breakage] and the scene now has " +
                                  (e_.breakage.enabled ? "it" : "none") + ": restart with the table as it was");
    else if (e_.breakage.enabled)
      breakage_.restoreState(b, model);
    if (every_ == 0) throw std::invalid_argument("sample every 0 steps (allowed: at least 1)");
  }

  std::string progress() const override {
    std::ostringstream s;
    s << product_.size() << (bonded_ ? " fragments discharged" : " balls discharged");
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
    if (bonded_) {
      nlohmann::json b;
      b["agglomerates"] = agglomerates_.size();
      b["fragments_discharged"] = product_.size();
      b["balls_per_fragment_max"] =
          fragment_balls_.empty() ? 0 : *std::max_element(fragment_balls_.begin(), fragment_balls_.end());
      b["single_balls_discharged"] = std::count(fragment_balls_.begin(), fragment_balls_.end(), std::size_t{1});
      double porosity = 0;
      for (const AgglomerateReport& a : agglomerates_) porosity += a.porosity / static_cast<double>(agglomerates_.size());
      b["porosity_mean"] = porosity;
      b["bonds"] = bonds_at_start_;
      b["bonds_intact_at_end"] = bonds_intact_;  // at the last sample; discharged fragments' bonds are gone
      b["bonds_intact_at_release"] = std::isnan(intact_at_release_) ? nlohmann::json(nullptr) : nlohmann::json(intact_at_release_);
      b["settle_bond_factor"] = e_.settle_bond_factor;
      b["strengths_restored_s"] = std::isnan(restored_at_) ? nlohmann::json(nullptr) : nlohmann::json(restored_at_);
      b["method"] = "fragments = balls joined by intact bonds; product when the centre of mass is below "
                    "discharge_height; diameter by Eq 6-15 with the agglomerate's porosity";
      c["bonded"] = b;
      c["method"] = "bonded feed: a fragment whose centre of mass is below discharge_height is product: removed, "
                    "its Eq 6-15 diameter and mass recorded (product.csv, id = its first ball); psd = mass fraction "
                    "of the product finer than each sieve size";
    }
    c["whiten"] = whiten_report;
    writeSeriesPlot("Mantle power (work of the moving walls on the balls)", "power (W)", "mantle and cap",
                    power_.series(), out_dir / "mantle_power.png", log);
    // The particle count over the run: breakage adds balls, discharge removes them.
    writeSeriesPlot("Balls in the run (feed, fragments; discharged ones leave)", "balls", "balls", ball_count_,
                    out_dir / "ball_count.png", log);
    if (!ball_count_.empty()) {
      const auto most = std::max_element(ball_count_.begin(), ball_count_.end(),
                                         [](const auto& a, const auto& b) { return a.second < b.second; });
      c["balls_max"] = static_cast<std::size_t>(most->second);
      c["balls_max_time_s"] = most->first;
    }
    if (e_.breakage.enabled) {
      nlohmann::json b = breakage_.report(e_.sieves_mm, out_dir);
      b["checks_from_s"] = breakageStart();
      // Breakage conserves mass to round-off: the feed is the product and what is left.
      b["mass_balance"] = {{"feed_kg", feed_mass},
                           {"product_kg", product_mass},
                           {"in_chamber_kg", chamber_mass_},
                           {"relative_difference", (feed_mass - product_mass - chamber_mass_) / feed_mass}};
      c["breakage"] = b;
    }
    r["crusher"] = c;
    if (e_.breakage.enabled) {
      // The breakage's cost beside the whole stepping (this run's, as wall_time_s).
      r["wall_time_s"]["breakage_checks"] = breakage_.checkSeconds();
      r["wall_time_s"]["breakage_freezes"] = breakage_.freezeSeconds();
    }
    log << "crusher: " << product_.size() << (bonded_ ? " fragments" : " balls") << " discharged (" << product_mass
        << " kg of " << feed_mass << " kg fed)";
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
  std::vector<AgglomerateReport> agglomerates_;    // the scene's, for the bonded feed
  bool bonded_ = false;                            // the world has bonds: discharge by fragments
  std::unordered_map<std::uint64_t, double> porosity_;  // ball id -> its agglomerate's porosity
  std::vector<std::size_t> fragment_balls_;        // balls of each discharged fragment
  std::vector<std::pair<double, double>> ball_count_;  // (s, balls in the run) every sample_interval
  double release_time_ = std::numeric_limits<double>::infinity();  // s, the stop wall goes
  /// s, the first breakage check (BreakageSettings::start): t = 0, or the release
  /// (t = 0 too in a scene without the stop wall: its feed falls into the chamber at once).
  double breakageStart() const {
    return e_.breakage.start == BreakageSettings::Start::Release && std::isfinite(release_time_) ? release_time_ : 0.0;
  }
  bool strengthened_ = false;
  double restored_at_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> tensile_, shear_;  // the strengths before settle_bond_factor
  std::size_t bonds_at_start_ = 0, bonds_intact_ = 0;
  double intact_at_release_ = std::numeric_limits<double>::quiet_NaN();

  /// What saveState writes and restoreState reads (but the breakage's own and the
  /// ball count): each
  /// member once, as f(key, member), for a const or a mutable self.
  template <class Self, class F>
  static void savedFields(Self& self, F&& f) {
    f("started", self.started_);
    f("every", self.every_);
    f("chamber_mass", self.chamber_mass_);
    f("product", self.product_);
    f("feed", self.feed_);
    f("entries", self.entries_);
    f("power", self.power_);
    f("metered_work", self.metered_work_);
    f("metered_time", self.metered_time_);
    f("events_seen", self.events_seen_);
    f("bonded", self.bonded_);
    f("porosity", self.porosity_);
    f("fragment_balls", self.fragment_balls_);
    f("strengthened", self.strengthened_);
    f("restored_at", self.restored_at_);  // NaN until the strengths are restored: CBOR keeps it
    f("tensile", self.tensile_);
    f("shear", self.shear_);
    f("bonds_at_start", self.bonds_at_start_);
    f("bonds_intact", self.bonds_intact_);
    f("intact_at_release", self.intact_at_release_);
  }

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

  /// A (time s, value) series against time, every sample_interval: mantle_power.png
  /// (the moving walls' power averaged over each interval), ball_count.png.
  static void writeSeriesPlot(const std::string& title, const std::string& y_label, const std::string& name,
                              const std::vector<std::pair<double, double>>& points, const std::filesystem::path& file,
                              std::ostream& log) {
    if (points.empty()) return;
    PlotSpec spec;
    spec.title = title;
    spec.x_label = "time (s)";
    spec.y_label = y_label;
    PlotSeries series{name, {}, {}, PlotSeries::Style::Line};
    for (const auto& [t, v] : points) {
      series.x.push_back(t);
      series.y.push_back(v);
    }
    spec.series = {series};
    try {
      writePlot(spec, file);
    } catch (const std::exception& e) {
      log << "crusher: no plot " << file.filename().string() << " (" << e.what() << ")\n";
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

std::shared_ptr<ExperimentSettings> readCrusherRunSettings(TableReader& t, const SettingsContext& context) {
  auto settings = std::make_shared<CrusherRunSettings>();
  settings->discharge_height = t.number("discharge_height", settings->discharge_height);
  if (t.has("sieves_mm")) {
    settings->sieves_mm = t.numberList("sieves_mm", Range::positive());
    if (!std::is_sorted(settings->sieves_mm.begin(), settings->sieves_mm.end()) || settings->sieves_mm.empty())
      t.fail("sieves_mm", "must be a non-empty list of sizes in increasing order (mm)");
  }
  settings->settle_bond_factor = t.number("settle_bond_factor", 1.0, Range::closed(1.0, 1e12));
  if (settings->settle_bond_factor != 1.0) {
    const auto& walls = context.model.walls;
    const auto stop = std::find_if(walls.begin(), walls.end(), [](const sim::Wall& w) { return w.name == kStopWall; });
    if (stop == walls.end() || !std::isfinite(stop->active_until))
      t.fail("settle_bond_factor", std::string("needs the feed bin's stop wall (a wall named ") + kStopWall +
                                       " that goes: crusher.feed_bin = true); the bonds are strong until it goes");
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
