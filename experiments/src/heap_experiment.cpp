// Heap test (experiments.md §b): the poured pebbles come to rest on the table;
// the angle of repose is measured from the final positions (heap_analysis.h).
#include <ostream>

#include "experiment.h"
#include "heap_analysis.h"
#include "plot.h"

namespace rocklab::experiments {

namespace {

class HeapExperiment final : public Experiment {
 public:
  explicit HeapExperiment(const Scene& scene) : e_(scene.experiment) {}

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext&) override {
    const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(e_.check_interval / world->dt())));
    if (world->stepCount() % every != 0) return true;
    const double t = world->time();
    speed_ = maxBallSpeed(world->particles());
    if (t < e_.settle_min_time) return true;
    settled_ = speed_ < e_.settle_speed;
    if (!settled_ && t < e_.settle_max_time) return true;
    settle_time_ = t;
    const auto& p = world->particles();
    balls_.clear();
    for (std::size_t i = 0; i < p.size(); ++i) balls_.push_back({p.position[i], p.radius[i]});
    return false;
  }

  std::string progress() const override {
    return "max speed " + std::to_string(speed_).substr(0, 6) + " m/s (settled below " +
           std::to_string(e_.settle_speed).substr(0, 6) + ")";
  }

  void report(nlohmann::json& r, const std::filesystem::path& out_dir, std::ostream& log) override {
    nlohmann::json h;
    h["settled"] = settled_;
    h["max_speed_mps"] = speed_;
    if (balls_.empty()) {
      r["angle_of_repose_deg"] = nullptr;
      h["note"] = "the run ended before the heap was measured (raise scene.end_time)";
      r["heap"] = h;
      log << "heap: not measured, the run ended first\n";
      return;
    }
    h["settle_time_s"] = settle_time_;
    try {
      const HeapAngle a = angleOfRepose(balls_, e_.base_z, e_.bin_width);
      r["angle_of_repose_deg"] = a.mean_deg;
      h["angle_std_deg"] = a.std_deg;
      h["flank_angles_deg"] = a.flank_deg;
      h["height_m"] = a.height_m;
      h["base_radius_m"] = a.base_radius_m;
      h["balls"] = a.balls;
      h["method"] = a.method;
      log << "heap: angle of repose " << a.mean_deg << " deg (flanks";
      for (double f : a.flank_deg) log << " " << f;
      log << "), height " << a.height_m << " m" << (settled_ ? "" : " — NOT settled (settle_max_time reached)") << "\n";
    } catch (const std::exception& ex) {
      r["angle_of_repose_deg"] = nullptr;
      h["note"] = std::string("no heap to measure: ") + ex.what();
      log << "heap: no angle: " << ex.what() << "\n";
    }
    r["heap"] = h;
    writeProfilePlot(out_dir / "heap_profile.png");
  }

 private:
  /// Side view of the heap: every ball's top against its distance from the axis.
  void writeProfilePlot(const std::filesystem::path& png) const {
    double cx = 0, cy = 0;
    for (const auto& b : balls_) {
      cx += b.centre.x() / static_cast<double>(balls_.size());
      cy += b.centre.y() / static_cast<double>(balls_.size());
    }
    PlotSeries s{"ball tops", {}, {}, PlotSeries::Style::Points};
    for (const auto& b : balls_) {
      s.x.push_back(std::hypot(b.centre.x() - cx, b.centre.y() - cy) * 1e3);
      s.y.push_back((b.centre.z() + b.radius - e_.base_z) * 1e3);
    }
    PlotSpec spec;
    spec.title = "heap: ball tops against distance from the heap axis";
    spec.x_label = "distance from axis (mm)";
    spec.y_label = "height above table (mm)";
    spec.series = {s};
    writePlot(spec, png);
  }

  ExperimentSettings e_;
  bool settled_ = false;
  double speed_ = 0, settle_time_ = 0;
  std::vector<geometry::Sphere> balls_;
};

}  // namespace

std::unique_ptr<Experiment> makeHeapExperiment(const Scene& scene) { return std::make_unique<HeapExperiment>(scene); }

}  // namespace rocklab::experiments
