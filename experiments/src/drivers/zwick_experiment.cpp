// Zwick crushing test (experiments.md §e, §f.2): a specimen (sphere, clump or
// bonded agglomerate) between two plane platens; optionally settled on the
// bottom one under gravity; then the top platen closes at a set speed. Each
// sample records the platens' loads (World::wallForces), their separation and
// the fragments (clusters of balls joined by intact bonds). Failure follows
// the lab's rule (§e): the pieces broken off the largest fragment exceed a
// third of the specimen's volume; the failure load is the peak load up to
// then, the strength sigma = F / d^2 (Eq 5-1) with d the platen separation at
// that peak.
#include "drivers/zwick_experiment.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <ostream>
#include <sstream>

#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "drivers/settle.h"

namespace rocklab::experiments {

namespace {

using geometry::Vec3;

/// One sample of the loading phase.
struct ZwickSample {
  double time = 0;              // s
  double travel = 0;            // m, top platen since loading started
  double gap = 0;               // m, platen separation
  double top_force = 0;         // N, load on the top platen (pushing it back)
  double bottom_force = 0;      // N, load on the bottom platen
  double largest_fraction = 1;  // of the specimen's volume in its largest fragment
  std::size_t intact_bonds = 0;
};

/// Fragments by volume: fractions of the whole, largest first.
std::vector<double> fragmentVolumes(const sim::ParticleState& p, const sim::BondState& bonds) {
  const std::vector<std::uint32_t> label = sim::bondedClusters(p.size(), bonds);
  std::vector<double> volume;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (label[i] >= volume.size()) volume.resize(label[i] + 1, 0.0);
    volume[label[i]] += 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius[i], 3);
  }
  std::sort(volume.begin(), volume.end(), std::greater<>());
  return volume;
}

class ZwickExperiment final : public Experiment {
 public:
  explicit ZwickExperiment(const Scene& scene)
      : s_(settingsOf<ZwickSettings>(scene)),
        settle_(s_.settle),
        sphere_count_(scene.spheres.size()),
        bond_count_(scene.bonds.size()),
        agglomerates_(scene.agglomerates) {}

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) override {
    if (sample_every_ == 0)
      sample_every_ = stepsIn(s_.sample_interval, world->dt());
    if (world->stepCount() % sample_every_ != 0) return true;
    if (phase_ == Phase::Settle) {
      collectBreaks(*world);  // a specimen may lose bonds while it settles
      if (s_.settle_first && !settle_.over(*world)) return true;
      startLoading(world, ctx);
      return true;
    }
    return sampleLoading(*world);
  }

  std::string progress() const override {
    std::ostringstream s;
    s.precision(4);
    if (phase_ == Phase::Settle) return "settling";
    s << "loading: travel " << (samples_.empty() ? 0.0 : samples_.back().travel * 1e3)
      << " mm, force " << (samples_.empty() ? 0.0 : samples_.back().top_force) << " N, peak "
      << peak_.top_force << " N" << (failed_ ? " (failed)" : "");
    return s.str();
  }

  void report(nlohmann::json& r, const std::filesystem::path& out, std::ostream& log) override;

 private:
  enum class Phase { Settle, Load };

  void startLoading(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    const sim::Model& model = world->model();
    top_ = wallIndex(model, s_.top_platen);
    bottom_ = wallIndex(model, s_.bottom_platen);
    up_ = model.walls[bottom_].normal.normalized();
    const sim::ParticleState& p = world->particles();
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t i = 0; i < p.size(); ++i) {
      lo = std::min(lo, p.position[i].dot(up_) - p.radius[i]);
      hi = std::max(hi, p.position[i].dot(up_) + p.radius[i]);
    }
    height_ = hi - lo;
    bottom_level_ = lo;
    top_start_ = hi + s_.start_gap;
    t_start_ = world->time();
    // The platens go where the specimen is: the bottom one touching its lowest
    // point (where it settled, or where the scene put it), the top one start_gap
    // above its highest, closing from now on (WallMotion runs from t = 0).
    switchPhase(world, ctx, [&](sim::Model& m) {
      sim::Wall& bottom = m.walls[bottom_];
      bottom.point += (lo - bottom.point.dot(up_)) * up_;
      bottom.motion = {};
      sim::Wall& top = m.walls[top_];
      top.point += (top_start_ - top.point.dot(up_)) * up_ + s_.platen_speed * t_start_ * up_;
      top.motion = {};
      top.motion.velocity = -s_.platen_speed * up_;
    });
    if (s_.sample_travel > 0)
      sample_every_ = stepsIn(s_.sample_travel / s_.platen_speed, world->dt());
    seen_breaks_ = 0;  // the settling World's log (collected by advance) went with it
    phase_ = Phase::Load;
    total_volume_ = 0;
    for (double r : world->particles().radius)
      total_volume_ += 4.0 / 3.0 * std::numbers::pi * r * r * r;
  }

  bool sampleLoading(const sim::World& world) {
    collectBreaks(world);
    const std::vector<Vec3> load = world.wallForces();
    ZwickSample x;
    x.time = world.time();
    x.travel = s_.platen_speed * (x.time - t_start_);
    x.gap = top_start_ - x.travel - bottom_level_;
    x.top_force = load[top_].dot(up_);
    x.bottom_force = -load[bottom_].dot(up_);
    x.intact_bonds = world.intactBonds();
    if (bond_count_ > 0) {
      const std::vector<double> v = fragmentVolumes(world.particles(), world.bonds());
      x.largest_fraction = v.front() / total_volume_;
      final_fragments_ = v;
    }
    samples_.push_back(x);
    if (!failed_ && x.top_force > peak_.top_force) peak_ = x;
    if (!failed_ && bond_count_ > 0 && 1.0 - x.largest_fraction > s_.failure_volume_fraction) {
      failed_ = true;
      failure_ = x;
    }
    if (failed_ && x.top_force < (1.0 - s_.end_drop) * peak_.top_force) return false;
    return x.travel < s_.start_gap + s_.max_strain * height_;
  }

  /// Every breakage of this World not yet seen (each World has its own log).
  void collectBreaks(const sim::World& world) {
    const auto& log = world.bondBreaks();
    for (; seen_breaks_ < log.size(); ++seen_breaks_) breaks_.push_back(log[seen_breaks_]);
  }

  void writeCurve(const std::filesystem::path& out) const;

  /// Mean (F_top - F_bottom) / F_top over the samples before the peak that carry
  /// at least a fifth of the peak load.
  double loadingImbalance() const {
    double sum = 0;
    std::size_t count = 0;
    for (const ZwickSample& x : samples_) {
      if (x.time >= peak_.time) break;
      if (x.top_force < 0.2 * peak_.top_force) continue;
      sum += (x.top_force - x.bottom_force) / x.top_force;
      ++count;
    }
    return count > 0 ? sum / static_cast<double>(count) : 0.0;
  }

  const ZwickSettings& s_;
  SettleDetector settle_;
  std::size_t sphere_count_, bond_count_;
  std::vector<AgglomerateReport> agglomerates_;
  Phase phase_ = Phase::Settle;
  std::uint64_t sample_every_ = 0;
  std::size_t top_ = 0, bottom_ = 0;
  Vec3 up_ = Vec3::UnitZ();
  double height_ = 0, bottom_level_ = 0, top_start_ = 0, t_start_ = 0, total_volume_ = 0;
  std::vector<ZwickSample> samples_;
  ZwickSample peak_, failure_;
  bool failed_ = false;
  std::vector<sim::BondBreak> breaks_;
  std::size_t seen_breaks_ = 0;
  std::vector<double> final_fragments_;  // m^3, at the last sample, largest first
};

void ZwickExperiment::writeCurve(const std::filesystem::path& out) const {
  std::ostringstream csv;
  csv.precision(10);
  csv << "time_s,travel_m,platen_gap_m,top_force_N,bottom_force_N,largest_fragment_fraction,intact_"
         "bonds\n";
  for (const ZwickSample& x : samples_)
    csv << x.time << ',' << x.travel << ',' << x.gap << ',' << x.top_force << ',' << x.bottom_force
        << ',' << x.largest_fraction << ',' << x.intact_bonds << '\n';
  detail::writeAtomically(out / "force_displacement.csv", csv.str());
  std::ostringstream breaks;
  breaks.precision(10);
  // Stresses for parallel bonds (0 for contact bonds), forces for both.
  breaks << "time_s,step,bond,ball_a,ball_b,kind,mode,tensile_stress_Pa,shear_stress_Pa,normal_force_N,"
            "shear_force_N\n";
  for (const sim::BondBreak& e : breaks_)
    breaks << e.time << ',' << e.step << ',' << e.bond << ',' << e.a << ',' << e.b << ','
           << sim::bondKindName(e.kind) << ',' << sim::bondFailureModeName(e.mode) << ','
           << e.tensile_stress << ',' << e.shear_stress << ',' << e.normal_force << ','
           << e.shear_force << '\n';
  if (bond_count_ > 0) detail::writeAtomically(out / "bond_breaks.csv", breaks.str());
  PlotSeries curve{"top platen", {}, {}, PlotSeries::Style::Line};
  for (const ZwickSample& x : samples_) {
    curve.x.push_back(x.travel * 1e3);
    curve.y.push_back(x.top_force * 1e-3);
  }
  PlotSpec spec;
  spec.title = "Zwick test: force against platen travel (" +
               std::to_string(s_.platen_speed * 1e3).substr(0, 5) + " mm/s)";
  spec.x_label = "top platen travel (mm)";
  spec.y_label = "force (kN)";
  spec.series.push_back(curve);
  if (failed_ || peak_.top_force > 0)
    spec.series.push_back({failed_ ? "failure load (peak before failure)" : "peak load",
                           {peak_.travel * 1e3},
                           {peak_.top_force * 1e-3},
                           PlotSeries::Style::Points});
  writePlot(spec, out / "force_displacement.png");
}

void ZwickExperiment::report(nlohmann::json& r, const std::filesystem::path& out,
                             std::ostream& log) {
  nlohmann::json z;
  z["platen_speed_mps"] = s_.platen_speed;
  z["specimen_height_m"] = height_;
  z["failed"] = failed_;
  z["samples"] = samples_.size();
  const double d = peak_.gap;
  const double strength = d > 0 ? peak_.top_force / (d * d) : 0.0;  // Eq 5-1
  z["peak_force_N"] = peak_.top_force;
  z["platen_gap_at_peak_m"] = d;
  z["strength_MPa"] = strength * 1e-6;
  z["strength_definition"] =
      "sigma = F / d^2 (Eq 5-1), F the peak load before failure, d the platen gap at it";
  // Quasi-static check: a specimen in equilibrium pushes both platens equally;
  // at a platen speed too fast for its stress waves the top one carries more.
  // At the peak itself breaking bonds send waves at any speed; the loading branch
  // below it shows the platen speed's own share.
  z["load_imbalance_at_peak"] =
      peak_.top_force > 0 ? (peak_.top_force - peak_.bottom_force) / peak_.top_force : 0.0;
  z["load_imbalance_loading"] = loadingImbalance();
  z["load_imbalance_definition"] =
      "(F_top - F_bottom) / F_top: at the peak sample, and its mean over the loading branch "
      "from 20 % of the peak load up to the peak; 0 for a quasi-static test";
  if (failed_) {
    z["failure_time_s"] = failure_.time;
    z["failure_travel_m"] = failure_.travel;
  }
  z["sphere_count"] = sphere_count_;
  z["bond_count"] = bond_count_;
  z["bonds_broken"] = breaks_.size();
  if (!agglomerates_.empty()) {
    z["porosity"] = agglomerates_.front().porosity;
    z["coordination_number"] = agglomerates_.front().coordination_number;
    z["agglomerate_bond_strength_Pa"] = agglomerates_.front().bond_strength;
  }
  if (!final_fragments_.empty() && total_volume_ > 0) {
    nlohmann::json f;
    f["count"] = final_fragments_.size();
    f["largest_fraction"] = final_fragments_[0] / total_volume_;
    f["second_fraction"] = final_fragments_.size() > 1 ? final_fragments_[1] / total_volume_ : 0.0;
    double fines = 0;
    const double fines_volume = std::numbers::pi / 6.0 * std::pow(s_.fines_size, 3);
    for (double v : final_fragments_)
      if (v < fines_volume) fines += v;
    f["fines_fraction"] = fines / total_volume_;
    f["fines_size_m"] = s_.fines_size;
    z["fragments"] = f;
  }
  for (const char* key : {"sphere_count", "bond_count", "bonds_broken", "peak_force_N",
                          "strength_MPa", "porosity", "coordination_number", "fragments"})
    if (z.contains(key)) r[key] = z[key];
  r["zwick"] = z;
  writeCurve(out);
  log << "zwick: peak force " << peak_.top_force << " N at a platen gap of " << d * 1e3
      << " mm: strength " << strength * 1e-6 << " MPa (Eq 5-1)"
      << (failed_ ? "" : "; no failure by the 1/3-volume rule") << "; bonds broken "
      << breaks_.size() << " of " << bond_count_ << "\n";
}

}  // namespace

std::unique_ptr<Experiment> makeZwickExperiment(const Scene& scene) {
  return std::make_unique<ZwickExperiment>(scene);
}

std::shared_ptr<ExperimentSettings> readZwickSettings(TableReader& t,
                                                      const SettingsContext& context) {
  auto e = std::make_shared<ZwickSettings>();
  auto platen = [&](const char* key, const std::string& fallback) {
    const std::string name = t.string(key, fallback);
    for (const sim::Wall& w : context.model.walls)
      if (w.name == name) {
        if (w.shape != sim::WallShape::Plane) t.fail(key, "wall '" + name + "' must be a plane");
        return name;
      }
    t.fail(key, "no wall called '" + name + "' in the scene");
  };
  e->bottom_platen = platen("bottom_platen", e->bottom_platen);
  e->top_platen = platen("top_platen", e->top_platen);
  if (e->top_platen == e->bottom_platen) t.fail("top_platen", "must differ from bottom_platen");
  e->platen_speed = t.number("platen_speed", e->platen_speed, Range::positive());
  e->settle_first = t.boolean("settle_first", e->settle_first);
  readSettleSettings(t, e->settle);
  e->start_gap = t.number("start_gap", e->start_gap, Range::nonNegative());
  e->sample_travel = t.number("sample_travel", e->sample_travel, Range::nonNegative());
  e->max_strain = t.number("max_strain", e->max_strain, {0.0, 1.0, true, false});
  e->failure_volume_fraction =
      t.number("failure_volume_fraction", e->failure_volume_fraction, {0.0, 1.0, true, false});
  e->end_drop = t.number("end_drop", e->end_drop, {0.0, 1.0, true, false});
  e->fines_size = t.number("fines_size", e->fines_size, Range::positive());
  return e;
}

}  // namespace rocklab::experiments
