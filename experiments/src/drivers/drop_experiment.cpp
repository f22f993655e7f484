// Drop test (experiments.md §a): one pebble dropped on a plate; the coefficient
// of restitution is the ratio of the normal speeds just after and just before
// the first impact (Eq 4-3, e = v_after / v_before), read from synchronised
// whole-step velocities of every step. Gravity acts during the contact too, so
// the measured e is lower than the contact law's by about g t_c / v (5e-4 for a
// 2 m/s impact and a 0.1 ms contact); the analytic curve of Eq 4-4 is reported
// beside it.
#include "drivers/drop_experiment.h"

#include <cmath>
#include <ostream>

#include "rocklab/sim/timestep.h"

namespace rocklab::experiments {

namespace {

class DropExperiment final : public Experiment {
 public:
  explicit DropExperiment(const Scene& scene) : beta_(scene.model.contact.damping_normal) {}

  bool wantsSnapshot(std::uint64_t) const override { return !done_; }

  void observe(const sim::Snapshot& s) override {
    const geometry::Vec3 up =
        gravity_.norm() > 0 ? geometry::Vec3(-gravity_.normalized()) : geometry::Vec3::UnitZ();
    const geometry::Vec3 v = s.clump_velocity.empty() ? s.velocity[0] : s.clump_velocity[0];
    const double vn = v.dot(up);
    const bool touching = s.wall_contacts + s.contacts > 0;
    if (!touching && !touched_) {
      v_before_ = vn;
      t_before_ = s.time;
    } else if (touching && !touched_) {
      touched_ = true;
      t_touch_ = s.time;
    } else if (!touching && touched_ && !done_) {
      v_after_ = vn;
      t_after_ = s.time;
      done_ = true;
    }
  }

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext&) override {
    gravity_ = world->gravity();
    return !done_;
  }

  std::string progress() const override { return touched_ ? "in contact" : "falling"; }

  void report(nlohmann::json& r, const std::filesystem::path&, std::ostream& log) override {
    nlohmann::json d;
    d["analytic_restitution"] = sim::restitutionFromDamping(beta_);  // Eq 4-4
    d["damping_ratio"] = beta_;
    if (done_ && v_before_ < 0) {
      const double e = -v_after_ / v_before_;
      d["restitution"] = e;
      d["impact_speed_mps"] = -v_before_;
      d["rebound_speed_mps"] = v_after_;
      d["contact_time_s"] = t_after_ - t_touch_;
      d["method"] =
          "e = v_after / v_before (Eq 4-3), normal velocity of the last step before and the first "
          "after the contact";
      r["restitution"] = e;
      log << "drop: restitution " << e << " (Eq 4-4 for beta = " << beta_ << ": "
          << d["analytic_restitution"].get<double>() << "), impact " << -v_before_
          << " m/s, contact " << (t_after_ - t_touch_) << " s\n";
    } else {
      d["restitution"] = nullptr;
      r["restitution"] = nullptr;
      log << "drop: no complete impact before the end of the run (raise scene.end_time)\n";
    }
    r["drop"] = d;
  }

 private:
  double beta_;
  geometry::Vec3 gravity_ = geometry::Vec3(0, 0, -9.81);
  bool touched_ = false, done_ = false;
  double v_before_ = 0, v_after_ = 0, t_before_ = 0, t_touch_ = 0, t_after_ = 0;
};

}  // namespace

std::unique_ptr<Experiment> makeDropExperiment(const Scene& scene) {
  return std::make_unique<DropExperiment>(scene);
}

std::shared_ptr<ExperimentSettings> readDropSettings(TableReader& /*table*/,
                                                     const SettingsContext& /*context*/) {
  return std::make_shared<DropSettings>();
}

}  // namespace rocklab::experiments
