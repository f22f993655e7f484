// Inclined chute and zoned chute (experiments.md §c, §d). Phases:
//   deposit  gravity tilted by deposit_inclination_deg (0 = vertical), gate
//            closed, until no ball is faster than settle_speed;
//            then temporary walls go, the top plate comes (bodies it cuts are
//            deleted) and the tracers are chosen: the bodies nearest the lab's
//            marker positions (5 columns x 4 against the camera wall, §c DEM 2);
//   tilt     gravity at the test inclination, gate still closed, tilt_steps
//            steps (the study's 5000 cycles of settling after the tilt, §c DEM 3);
//   flow     gate removed; every sample_interval (500 fps like the lab camera)
//            the markers' travel along the base is sampled, and bodies past the
//            outlet are counted as discharged; bodies remove_beyond past the
//            outlet are deleted. Ends when every body is out (clearance) or
//            when none left for jam_time (jammed).
// Chute frame: outlet at x = 0, feed end at x = length, base z = 0, camera wall
// y = 0; the tilt turns gravity instead of the geometry (§c DEM 4).
#include "drivers/chute_experiment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include "analysis/marker_tracking.h"
#include "analysis/plot.h"
#include "analysis/tracking_report.h"
#include "camera/camera_calibration.h"
#include "camera/camera_recorder.h"
#include "common/atomic_file.h"
#include "common/json_text.h"
#include "drivers/settle.h"
#include "rocklab/sim/wall_motion.h"
#include "rocklab/track/export.h"

namespace rocklab::experiments {

namespace {

using geometry::Vec3;

struct Marker {
  std::uint64_t id = 0;
  int column = 0;              // 1 = nearest the outlet
  int row = 0;                 // 1 = lowest
  Vec3 target = Vec3::Zero();  // m, the lab position it stands for
  Vec3 start = Vec3::Zero();   // m, position when the gate opened
  double last_travel = 0.0, last_time = 0.0;
  double onset_time =
      std::numeric_limits<double>::quiet_NaN();  // s after gate opening: travel reached kOnset
  double travel_time = std::numeric_limits<double>::quiet_NaN();  // s after gate opening: travel
                                                                  // reached measure_distance
  double velocity = std::numeric_limits<double>::quiet_NaN();     // m/s over the first
                                                               // measure_distance of its own motion
  double velocity_from_gate =
      std::numeric_limits<double>::quiet_NaN();  // m/s, measure_distance / travel_time
};

constexpr double kOnset = 0.002;  // m of travel that marks the start of a marker's motion

// A restart's state (saveState): every member, NaN included (CBOR keeps it).
std::array<double, 3> asArray(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
Vec3 asVec3(const nlohmann::json& j) {
  const auto a = j.get<std::array<double, 3>>();
  return {a[0], a[1], a[2]};
}
void to_json(nlohmann::json& j, const Marker& m) {
  j = {{"id", m.id},
       {"column", m.column},
       {"row", m.row},
       {"target", asArray(m.target)},
       {"start", asArray(m.start)},
       {"last_travel", m.last_travel},
       {"last_time", m.last_time},
       {"onset_time", m.onset_time},
       {"travel_time", m.travel_time},
       {"velocity", m.velocity},
       {"velocity_from_gate", m.velocity_from_gate}};
}
void from_json(const nlohmann::json& j, Marker& m) {
  j.at("id").get_to(m.id);
  j.at("column").get_to(m.column);
  j.at("row").get_to(m.row);
  m.target = asVec3(j.at("target"));
  m.start = asVec3(j.at("start"));
  j.at("last_travel").get_to(m.last_travel);
  j.at("last_time").get_to(m.last_time);
  j.at("onset_time").get_to(m.onset_time);
  j.at("travel_time").get_to(m.travel_time);
  j.at("velocity").get_to(m.velocity);
  j.at("velocity_from_gate").get_to(m.velocity_from_gate);
}

class ChuteExperiment final : public Experiment {
 public:
  explicit ChuteExperiment(const Scene& scene)
      : e_(settingsOf<ChuteSettings>(scene)), g_(scene.model.gravity.norm()), settle_(e_.settle) {
    for (const CameraSettings& c : scene.cameras)
      if (c.name == e_.track_camera) {
        tracking_ = std::make_unique<MarkerTracking>(c.camera, kOnset, e_.measure_distance);
        track_settings_ = c;
      }
    // Size of a marker pebble: the clump's equivalent sphere, or the largest sphere.
    if (!scene.clump_shapes.empty())
      marker_radius_ = 0.5 * scene.clump_shapes.front().equivalent_diameter;
    for (const auto& s : scene.spheres) marker_radius_ = std::max(marker_radius_, s.radius);
  }

  std::string trackingCamera() const override {
    return tracking_ ? e_.track_camera : std::string();
  }  // read once at start
  void cameraFrame(std::uint64_t frame, double time, const cv::Mat& raw) override {
    if (tracking_ && !markers_.empty())
      tracking_->addFrame(frame, time, raw);  // red exists once markers are chosen
  }

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) override {
    if (phase_ == Phase::Done) return false;
    if (phase_ == Phase::Start) {
      every_ = stepsIn(e_.sample_interval, world->dt());
      switchPhase(world, ctx, [&](sim::Model& m) { depositModel(m); });
      phase_ = Phase::Deposit;
      bodies_total_ = indexBodies(world->particles()).size();
    }
    if (restored_) {  // the bodies' places in the World the checkpoint made
      bodies_ = indexBodies(world->particles());
      restored_ = false;
    }
    const std::uint64_t step = world->stepCount();
    if (phase_ == Phase::Tilt) {
      if (step < tilt_end_step_) return true;
      openGate(world, ctx);
      return true;
    }
    if (stoppedAfterDeposit()) {  // restarted from a run that stopped after its deposit
      endDeposit(world, ctx);
      return true;
    }
    if (step % every_ != 0) return true;
    if (phase_ == Phase::Deposit) {
      const bool only_kept = !e_.top_wall.empty() && e_.settle_scope == "kept";
      if (!settle_.over(*world, only_kept ? cutByTop(world->particles(), topPlane(world->model())) : std::vector<bool>{}))
        return true;
      if (e_.stop_after == "deposit") {  // the state a restart places its own top plate into
        deposit_over_ = true;
        deposit_time_ = world->time();
        bed_height_ = bedHeight(world->particles());
        return false;
      }
      endDeposit(world, ctx);
      return true;
    }
    return sampleFlow(world, ctx);
  }

  std::string progress() const override {
    std::ostringstream s;
    s << std::setprecision(3);
    switch (phase_) {
      case Phase::Start:
      case Phase::Deposit:
        s << (deposit_over_ ? "deposit over" : "deposit") << ", max speed " << settle_.maxSpeed() << " m/s";
        break;
      case Phase::Tilt:
        s << "tilt";
        break;
      case Phase::Flow:
        s << "flow, " << (bodies_total_ - discharged_count_) << " bodies in the chute";
        break;
      case Phase::Done:
        s << "done";
        break;
    }
    return s.str();
  }

  void report(nlohmann::json& r, const std::filesystem::path& out_dir, std::ostream& log) override;
  nlohmann::json reportTracking(nlohmann::json& markers, const std::filesystem::path& out_dir,
                                std::ostream& log) const;

  std::unordered_set<std::uint64_t> markerBodies() const override {
    std::unordered_set<std::uint64_t> ids;
    for (const Marker& m : markers_) ids.insert(m.id);
    return ids;
  }

  bool restartable() const override { return true; }
  bool endsBeforeStep() const override { return stoppedAfterDeposit(); }

  nlohmann::json saveState() const override {
    nlohmann::json j;
    savedFields(*this, [&j](const char* key, const auto& value) { j[key] = value; });
    std::vector<std::uint64_t> discharged(discharged_.begin(), discharged_.end());
    std::sort(discharged.begin(), discharged.end());
    j["discharged"] = discharged;
    j["top_point"] = asArray(top_point_);
    j["top_normal"] = asArray(top_normal_);
    j["deposit_over"] = deposit_over_;
    return j;
  }

  /// The phase, its figures so far and the model of that phase (gravity, the walls
  /// placed or gone at the saved times). The tracker's frames are not saved: a
  /// chute filmed for tracking restarts from its deposit only.
  void restoreState(const nlohmann::json& j, sim::Model& model) override {
    savedFields(*this, [&j](const char* key, auto& value) { j.at(key).get_to(value); });
    const auto discharged = j.at("discharged").get<std::vector<std::uint64_t>>();
    discharged_ = {discharged.begin(), discharged.end()};
    top_point_ = asVec3(j.at("top_point"));
    top_normal_ = asVec3(j.at("top_normal"));
    deposit_over_ = j.value("deposit_over", false);  // absent in checkpoints before stop_after
    if (phase_ < Phase::Start || phase_ > Phase::Done)
      throw std::invalid_argument("phase " + std::to_string(static_cast<int>(phase_)) + " (allowed: 0 to 4)");
    if (every_ == 0) throw std::invalid_argument("sample every 0 steps (allowed: at least 1)");
    if (!tracking_error_.empty()) tracking_.reset();
    if (tracking_ && phase_ >= Phase::Tilt)
      throw std::invalid_argument("saved after the deposit of a run that tracks camera '" + e_.track_camera +
                                  "': the tracker's frames are not in a checkpoint (a tracked chute restarts from a "
                                  "checkpoint of its deposit, or run the scene again)");
    if (phase_ >= Phase::Deposit) depositModel(model);
    if (phase_ >= Phase::Tilt) testModel(model, deposit_time_);
    if (phase_ >= Phase::Flow) gateModel(model, gate_time_);
    restored_ = true;
  }

 private:
  enum class Phase { Start, Deposit, Tilt, Flow, Done };

  /// The top plate's lower face: a point and the normal facing down into the channel.
  struct TopPlane {
    Vec3 point = Vec3::Zero(), normal = -Vec3::UnitZ();
  };
  TopPlane topPlane(const sim::Model& model) const {
    const sim::Wall& top = model.walls[wallIndex(model, e_.top_wall)];
    TopPlane plane{top.point, top.normal};
    if (top.shape == sim::WallShape::Polygon) {
      plane.normal = sim::polygonNormal(top.vertices);
      plane.point = top.vertices[0];
    }
    if (plane.normal.z() > 0) plane.normal = -plane.normal;
    return plane;
  }
  /// The balls the plate cuts (or that lie beyond it): deleted when it is placed (§d DEM 3).
  static std::vector<bool> cutByTop(const sim::ParticleState& p, const TopPlane& top) {
    std::vector<bool> cut(p.size(), false);
    for (std::size_t i = 0; i < p.size(); ++i) cut[i] = top.normal.dot(p.position[i] - top.point) < p.radius[i];
    return cut;
  }

  // The model of each phase, from the time it began: the run's phase switches and
  // a restart (restoreState) make it the same way.
  void depositModel(sim::Model& m) const {
    m.gravity = tiltedGravity(g_, e_.deposit_inclination_deg, e_.rotate_gravity);
    m.gravity_changes.clear();  // the experiment owns gravity
    if (!e_.top_wall.empty())
      m.walls[wallIndex(m, e_.top_wall)].active_from = std::numeric_limits<double>::max();  // until placed
  }
  /// From `t` (the deposit's end): temporary walls gone, the top plate placed, gravity at the test angle.
  void testModel(sim::Model& m, double t) const {
    for (const std::string& name : e_.temporary_walls) m.walls[wallIndex(m, name)].active_until = t;
    if (!e_.top_wall.empty()) m.walls[wallIndex(m, e_.top_wall)].active_from = t;
    m.gravity = tiltedGravity(g_, e_.inclination_deg, e_.rotate_gravity);
  }
  void gateModel(sim::Model& m, double t) const { m.walls[wallIndex(m, e_.gate_wall)].active_until = t; }

  /// What saveState writes and restoreState reads (but the discharged ids and the
  /// top plate's plane): each member once, as f(key, member), for a const or a
  /// mutable self.
  template <class Self, class F>
  static void savedFields(Self& self, F&& f) {
    f("phase", self.phase_);
    f("every", self.every_);
    f("tilt_end_step", self.tilt_end_step_);
    f("bodies_total", self.bodies_total_);
    f("removed_by_top", self.removed_by_top_);
    f("settle", self.settle_);
    f("jammed", self.jammed_);
    f("deposit_time", self.deposit_time_);
    f("gate_time", self.gate_time_);
    f("last_discharge", self.last_discharge_);
    f("clearance_time", self.clearance_time_);
    f("bed_height", self.bed_height_);
    f("markers", self.markers_);
    f("discharged_count", self.discharged_count_);
    f("discharged_mass", self.discharged_mass_);
    f("discharge_curve", self.discharge_curve_);
    f("checks_since_removal", self.checks_since_removal_);
    f("has_top", self.has_top_);
    f("tracking_error", self.tracking_error_);
  }

  /// 95th percentile of the ball tops (robust to a few loose balls), m.
  static double bedHeight(const sim::ParticleState& p) {
    std::vector<double> tops;
    for (std::size_t i = 0; i < p.size(); ++i) tops.push_back(p.position[i].z() + p.radius[i]);
    if (tops.empty()) return 0.0;
    std::sort(tops.begin(), tops.end());
    return tops[static_cast<std::size_t>(0.95 * static_cast<double>(tops.size() - 1))];
  }

  /// The deposit is over (stop_after) and the top plate not yet placed: the run
  /// ends here, and a restart from here places its plate first.
  bool stoppedAfterDeposit() const { return phase_ == Phase::Deposit && deposit_over_; }

  void endDeposit(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    const double t = world->time();
    deposit_time_ = t;
    const sim::ParticleState& p = world->particles();
    // Bodies cut by (or beyond) the top plate go: the plate is placed into the
    // deposited bed, as in the study's zoned chute (§d DEM 3).
    std::vector<bool> remove;
    if (!e_.top_wall.empty()) {
      const TopPlane top = topPlane(world->model());
      has_top_ = std::abs(top.normal.z()) > 1e-9;
      top_point_ = top.point;
      top_normal_ = top.normal;
      remove = cutByTop(p, top);
    }
    bed_height_ = bedHeight(p);
    switchPhase(
        world, ctx, [&](sim::Model& m) { testModel(m, t); }, remove);
    bodies_ = indexBodies(world->particles());
    removed_by_top_ = bodies_total_ - bodies_.size();
    bodies_total_ = bodies_.size();
    calibrateTrackingCamera();
    chooseMarkers(world->particles());
    if (tracking_ && e_.track_position == "shape") useMarkerShape(world->particles());
    tilt_end_step_ = world->stepCount() + e_.tilt_steps;
    phase_ = Phase::Tilt;
  }

  /// Calibrates the tracked camera from checkerboard photos on the camera-side wall
  /// (exact camera with calibration_photos = 0) and gives the tracker the marker size.
  void calibrateTrackingCamera() {
    // The lab calibrates its camera on the camera-side wall (y = 0, seen from -y)
    // and knows how big its markers are and that they lie against that wall:
    // their centres one (equivalent) radius behind it.
    if (!tracking_) return;
    try {
      if (e_.calibration_photos > 0) {
        const WallCalibration cal =
            calibrateOnWall(track_settings_.camera, renderOptionsFor(track_settings_), Vec3::Zero(),
                            -Vec3::UnitY(), e_.calibration_photos);
        tracking_->setCamera(cal.camera);
        calibration_report_ = cal.report;
      }
      tracking_->setMarkers(marker_radius_, marker_radius_);
    } catch (const std::exception& e) {
      // No calibrated camera, no tracking: the run goes on for the DEM truth and
      // results.json says why nothing was tracked.
      tracking_error_ = std::string("camera calibration failed: ") + e.what();
      tracking_.reset();
    }
  }

  /// The bodies nearest the lab marker positions, each taken once (column 1 first,
  /// bottom up). The lab paints pebbles that touch the camera-side wall (y = 0), so
  /// by default bodies with a ball within a tenth of the median ball radius of that
  /// wall and within three marker radii of the target in x-z come first (nearest in
  /// x-z); otherwise, and with experiment.marker_y set, the body nearest in 3-d to
  /// (x, marker_y or the median radius, z).
  void chooseMarkers(const sim::ParticleState& p) {
    std::vector<double> r(p.radius);
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    const double median_radius = r.empty() ? 0.0 : r[r.size() / 2];
    const bool at_wall = e_.marker_y <= 0;
    std::unordered_map<std::uint64_t, double>
        wall_gap;  // body id -> smallest y - radius of its balls
    for (std::size_t i = 0; i < p.size(); ++i) {
      const bool member = !p.clump.empty() && p.clump[i] >= 0;
      const std::uint64_t id = member ? p.clumps.id[static_cast<std::size_t>(p.clump[i])] : p.id[i];
      const double gap = p.position[i].y() - p.radius[i];
      const auto [it, fresh] = wall_gap.emplace(id, gap);
      if (!fresh) it->second = std::min(it->second, gap);
    }
    std::vector<std::uint64_t> taken;
    for (std::size_t c = 0; c < e_.marker_columns.size(); ++c) {
      // Heights in metres, or as fractions of the channel height at the column
      // (the zoned chute's markers sit in the mid-layer of each zone, §d).
      const double x = e_.marker_columns[c];
      std::vector<double> heights = e_.marker_heights;
      for (double f : e_.marker_height_fractions) heights.push_back(f * channelHeight(x));
      for (std::size_t h = 0; h < heights.size(); ++h) {
        Marker m;
        m.column = static_cast<int>(c) + 1;
        m.row = static_cast<int>(h) + 1;
        m.target = Vec3(x, at_wall ? median_radius : e_.marker_y, heights[h]);
        // Against the wall within three marker radii of the target if such a body
        // is left, else the nearest of all.
        double best = std::numeric_limits<double>::infinity();
        for (const bool wall_only : {at_wall, false}) {
          for (const auto& [id, ref] : bodies_) {
            if (wall_only && wall_gap.at(id) > 0.1 * median_radius) continue;
            Vec3 d = bodyPosition(p, ref) - m.target;
            if (wall_only) d.y() = 0.0;
            if (wall_only && d.norm() > 3.0 * marker_radius_) continue;
            if (d.squaredNorm() < best &&
                std::find(taken.begin(), taken.end(), id) == taken.end()) {
              best = d.squaredNorm();
              m.id = id;
            }
          }
          if (std::isfinite(best)) break;
        }
        if (!std::isfinite(best)) continue;  // fewer bodies than markers
        taken.push_back(m.id);
        markers_.push_back(m);
      }
    }
  }

  /// The shape fit needs what the lab knows of its markers: their clump shapes,
  /// touching the camera-side wall. Each marker's balls about its centre of mass give
  /// its shape; markers of several shapes (the zoned chute's three clump sizes) give
  /// the fit several to choose among, one a track. Markers placed off the wall
  /// (marker_y) keep the centroid (shape_fit_skipped_ says why).
  void useMarkerShape(const sim::ParticleState& p) {
    if (markers_.empty()) return;
    if (e_.marker_y > 0) {
      shape_fit_skipped_ = "experiment.marker_y places the markers off the wall";
      return;
    }
    auto ballsOf = [&](std::uint64_t id) {
      std::vector<geometry::Sphere> balls;
      const BodyRef& ref = bodies_.at(id);
      const Vec3 centre = bodyPosition(p, ref);
      if (!ref.clump) return std::vector<geometry::Sphere>{{Vec3::Zero(), p.radius[ref.index]}};
      for (std::uint32_t m = p.clumps.member_begin[ref.index]; m < p.clumps.member_begin[ref.index + 1]; ++m) {
        const std::uint32_t ball = p.clumps.member_ball[m];
        balls.push_back({p.position[ball] - centre, p.radius[ball]});
      }
      return balls;
    };
    // One shape per set of member radii: the members of one clump type, wherever it
    // lies, have the same radii in the same order (the offsets turn with the clump).
    auto sameShape = [](const std::vector<geometry::Sphere>& a, const std::vector<geometry::Sphere>& b) {
      bool same = a.size() == b.size();
      for (std::size_t k = 0; same && k < a.size(); ++k)
        same = std::abs(a[k].radius - b[k].radius) <= 1e-9 * a[k].radius;
      return same;
    };
    std::vector<std::vector<geometry::Sphere>> shapes;
    for (const Marker& m : markers_) {
      std::vector<geometry::Sphere> balls = ballsOf(m.id);
      if (std::none_of(shapes.begin(), shapes.end(), [&](const auto& s) { return sameShape(s, balls); }))
        shapes.push_back(std::move(balls));
    }
    tracking_->useShapeFit(shapes);
  }

  /// Height of the channel above the base at x: under the top plate, else the bed.
  double channelHeight(double x) const {
    if (!has_top_) return bed_height_;
    // Plane through top_point_ with normal top_normal_: solve for z at (x, y = 0).
    return top_point_.z() -
           (top_normal_.x() * (x - top_point_.x()) + top_normal_.y() * (0.0 - top_point_.y())) /
               top_normal_.z();
  }

  void openGate(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    const double t = world->time();
    switchPhase(world, ctx, [&](sim::Model& m) { gateModel(m, t); });
    gate_time_ = last_discharge_ = t;
    // The lab sees the gate open in its film: travel counts from there, as the
    // truth's does (the bed creeps a few mm while the chute tilts; that must not count).
    if (tracking_) tracking_->setReferenceTime(t);
    bodies_ = indexBodies(world->particles());
    for (Marker& m : markers_) m.start = bodyPosition(world->particles(), bodies_.at(m.id));
    truth_ = MarkerTruth(markers_.size());
    for (std::size_t k = 0; k < markers_.size(); ++k) truth_.add(k, t, markers_[k].start);
    phase_ = Phase::Flow;
  }

  bool sampleFlow(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx) {
    const double t = world->time();
    const sim::ParticleState& p = world->particles();
    // Markers: travel along the base towards the outlet (-x). The mean velocity
    // over the first measure_distance of a marker's motion (§c step 5) runs from
    // its onset (travel kOnset, so a marker upstream is not charged for the time
    // the flow front took to reach it) to measure_distance; both moments are
    // interpolated between samples. The velocity counted from the gate opening
    // is kept too.
    const double now = t - gate_time_;
    auto crossing = [&](const Marker& m, double travel, double level) {
      const double f = (level - m.last_travel) / std::max(travel - m.last_travel, 1e-300);
      return m.last_time + f * (now - m.last_time);
    };
    for (std::size_t k = 0; k < markers_.size(); ++k) {
      Marker& m = markers_[k];
      const auto it = bodies_.find(m.id);
      if (it == bodies_.end()) continue;
      if (tracking_) truth_.add(k, t, bodyPosition(p, it->second));  // for the tracking-error report
      if (std::isfinite(m.velocity)) continue;
      const double travel = m.start.x() - bodyPosition(p, it->second).x();
      if (!std::isfinite(m.onset_time) && travel >= kOnset)
        m.onset_time = crossing(m, travel, kOnset);
      if (travel >= e_.measure_distance) {
        m.travel_time = crossing(m, travel, e_.measure_distance);
        m.velocity = (e_.measure_distance - kOnset) / (m.travel_time - m.onset_time);
        m.velocity_from_gate = e_.measure_distance / m.travel_time;
      }
      m.last_travel = travel;
      m.last_time = now;
    }
    // Discharge: a body is out once its centre passed the outlet.
    bool far_out = false;
    for (const auto& [id, ref] : bodies_) {
      const double x = bodyPosition(p, ref).x();
      if (x < 0 && discharged_.insert(id).second) {
        ++discharged_count_;
        discharged_mass_ += bodyMass(p, ref);
        discharge_curve_.emplace_back(t - gate_time_, discharged_mass_);
        last_discharge_ = t;
      }
      far_out = far_out || x < -e_.remove_beyond;
    }
    if (discharged_count_ == bodies_total_) {
      clearance_time_ = last_discharge_ - gate_time_;
      phase_ = Phase::Done;
      return false;
    }
    if (t - last_discharge_ > e_.jam_time) {
      jammed_ = true;
      phase_ = Phase::Done;
      return false;
    }
    // Delete bodies well past the outlet (every 10 checks): they only fall.
    if (far_out && ++checks_since_removal_ >= 10) {
      checks_since_removal_ = 0;
      std::vector<bool> remove(p.size(), false);
      for (std::size_t i = 0; i < p.size(); ++i) remove[i] = p.position[i].x() < -e_.remove_beyond;
      // withoutBalls removes whole clumps; keep a clump with any member still near the outlet.
      for (std::size_t c = 0; c < p.clumps.size(); ++c) {
        bool all = true;
        for (std::uint32_t k = p.clumps.member_begin[c]; k < p.clumps.member_begin[c + 1]; ++k)
          all = all && remove[p.clumps.member_ball[k]];
        if (!all)
          for (std::uint32_t k = p.clumps.member_begin[c]; k < p.clumps.member_begin[c + 1]; ++k)
            remove[p.clumps.member_ball[k]] = false;
      }
      switchPhase(
          world, ctx, [](sim::Model&) {}, remove);
      bodies_ = indexBodies(world->particles());
    }
    return true;
  }

  /// experiment.measure_distance as the plots print it, e.g. "100 mm".
  std::string measureDistanceText() const {
    std::ostringstream text;
    text << e_.measure_distance * 1e3 << " mm";
    return text.str();
  }

  ChuteSettings e_;
  double g_;
  Phase phase_ = Phase::Start;
  std::uint64_t every_ = 1, tilt_end_step_ = 0;
  std::unordered_map<std::uint64_t, BodyRef> bodies_;
  std::size_t bodies_total_ = 0, removed_by_top_ = 0;
  SettleDetector settle_;
  bool jammed_ = false;
  double deposit_time_ = std::numeric_limits<double>::quiet_NaN();
  double gate_time_ = std::numeric_limits<double>::quiet_NaN(), last_discharge_ = 0;
  double clearance_time_ = std::numeric_limits<double>::quiet_NaN(), bed_height_ = 0;
  std::vector<Marker> markers_;
  std::unordered_set<std::uint64_t> discharged_;
  std::size_t discharged_count_ = 0;
  double discharged_mass_ = 0;
  std::vector<std::pair<double, double>> discharge_curve_;  // (s after gate opening, kg)
  int checks_since_removal_ = 0;
  bool deposit_over_ = false;  // stopped after the deposit (stop_after), the top plate not yet placed
  bool restored_ = false;  // by restoreState: bodies_ is made again from the World at the next advance
  std::unique_ptr<MarkerTracking> tracking_;
  MarkerTruth truth_;  // marker centres at every sample from the gate opening (tracking report only)
  CameraSettings
      track_settings_;  // the tracked camera as the renderer has it (takes the calibration photos)
  nlohmann::json calibration_report_;  // recovered against true camera (null: exact camera used)
  std::string tracking_error_;         // why there is no tracking ("" = none or it ran)
  std::string shape_fit_skipped_;      // why track_position = "shape" fell back to the centroid
  double marker_radius_ = 0.0;         // m
  bool has_top_ = false;
  Vec3 top_point_ = Vec3::Zero(), top_normal_ = Vec3::UnitZ();
};

/// The tracked velocities (images only) beside the truth: each truth marker takes
/// the track that started nearest to it (x-z, within 3 marker radii, each track once) —
/// the comparison reads both, the tracker never did. Adds tracked_velocity_mps
/// to `markers`, writes tracks.csv and tracked_vs_truth.png; returns the summary.
nlohmann::json ChuteExperiment::reportTracking(nlohmann::json& markers,
                                               const std::filesystem::path& out_dir,
                                               std::ostream& log) const {
  if (!tracking_error_.empty()) {
    log << "tracking: none (" << tracking_error_ << ")\n";
    return {{"camera", e_.track_camera}, {"error", tracking_error_}};
  }
  if (!tracking_ || markers_.empty()) return nullptr;
  const MarkerTracking::Result t = tracking_->finish();
  track::writeTracksCsv(out_dir / "tracks.csv", t.tracks, tracking_->camera(),
                        tracking_->planePoint(), Vec3::UnitY());
  std::vector<bool> used(t.tracks.size(), false);
  double sum2 = 0, sum2_rel = 0, max_abs = 0, max_rel = 0;
  int compared = 0, tracked = 0;
  struct Errors {
    double sum2_rel = 0, max_rel = 0;
    int compared = 0;
  };
  std::vector<Errors> variant_errors(t.depth_variants.size());  // the shape fit's other depths
  PlotSeries points{"markers", {}, {}, PlotSeries::Style::Points};
  for (std::size_t k = 0; k < markers_.size(); ++k) {
    const Marker& m = markers_[k];
    int best = -1;
    double best_d = 3.0 * marker_radius_;  // m: a blob centroid may sit a radius off
    for (std::size_t j = 0; j < t.velocities.size(); ++j) {
      if (used[j]) continue;
      const Vec3 d = t.velocities[j].start_world - m.start;
      const double dist = std::hypot(d.x(), d.z());
      if (dist < best_d) {
        best_d = dist;
        best = static_cast<int>(j);
      }
    }
    nlohmann::json& out = markers[k];
    out["track_id"] = best >= 0 ? nlohmann::json(t.tracks[static_cast<std::size_t>(best)].id)
                                : nlohmann::json(nullptr);
    const double v = best >= 0 ? t.velocities[static_cast<std::size_t>(best)].velocity
                               : std::numeric_limits<double>::quiet_NaN();
    if (best >= 0) used[static_cast<std::size_t>(best)] = true;
    out["tracked_velocity_mps"] = detail::finiteOrNull(v);
    if (std::isfinite(v)) ++tracked;
    for (std::size_t d = 0; best >= 0 && d < t.depth_variants.size() && std::isfinite(m.velocity); ++d) {
      const double other = t.depth_variants[d].second[static_cast<std::size_t>(best)].velocity;
      if (!std::isfinite(other)) continue;
      const double rel = (other - m.velocity) / m.velocity;
      variant_errors[d].sum2_rel += rel * rel;
      variant_errors[d].max_rel = std::max(variant_errors[d].max_rel, std::abs(rel));
      ++variant_errors[d].compared;
    }
    if (std::isfinite(v) && std::isfinite(m.velocity)) {
      const double err = v - m.velocity;
      sum2 += err * err;
      sum2_rel += (err / m.velocity) * (err / m.velocity);
      max_abs = std::max(max_abs, std::abs(err));
      max_rel = std::max(max_rel, std::abs(err / m.velocity));
      ++compared;
      points.x.push_back(m.velocity);
      points.y.push_back(v);
    }
  }
  nlohmann::json s = {
      {"camera", e_.track_camera},
      {"frames", t.frames.size()},
      {"tracks", t.tracks.size()},
      {"markers_tracked", tracked},
      {"markers_compared", compared},
      {"tracking_s", t.seconds},
      {"frames_per_s", t.seconds > 0 ? static_cast<double>(t.frames.size()) / t.seconds : 0.0},
      {"position", t.shape_fit ? "shape" : "centroid"},
      {"method",
       std::string("HSV red segmentation, redness-weighted centroids, merged blobs split at the tracks' predictions, "
                   "Hungarian linking with constant-velocity prediction, tracks stitched across gaps; ") +
           (t.shape_fit ? "position: the marker clump's projected outline fitted to the blob's sub-pixel edges "
                          "(Levenberg-Marquardt, seeded from the track's previous pose, multi-start at a track's "
                          "first frame or after a poor fit, where markers of several shapes each shape tried and the "
                          "smallest edge residual kept), its depth from the clump touching the camera wall"
                        : "position: the centroid, pixel -> world on the plane of the marker centres") +
           "; velocity from 2 mm to measure_distance of travel along the base, as the truth"},
      {"calibration", calibration_report_}};
  if (t.shape_fit)
    s["shape_fit"] = {{"shapes", t.shapes},
                      {"fitted", t.shape_fit_counts.fitted},
                      {"searched", t.shape_fit_counts.searched},
                      {"shape_choices", t.shape_fit_counts.shape_choices},
                      {"unfitted", t.shape_fit_counts.unfitted},
                      {"duplicates_withdrawn", t.shape_fit_counts.duplicates}};
  else if (e_.track_position == "shape")
    s["shape_fit"] = {{"skipped", shape_fit_skipped_}};
  s["error_report"] =
      trackingErrorReport(*tracking_, t, truth_, track_settings_.camera, markers, out_dir / "tracking_error.png",
                          out_dir / "tracking_pairs.csv");
  {
    const nlohmann::json& er = s["error_report"];
    log << std::defaultfloat << std::setprecision(3) << "tracking error per frame (" << er["pairs"].get<int>()
        << " marker-frames): u bias " << er["pixel_error"]["u"]["bias_px"].get<double>() << " px, RMS "
        << er["pixel_error"]["u"]["rms_px"].get<double>() << " px; v bias "
        << er["pixel_error"]["v"]["bias_px"].get<double>() << " px, RMS "
        << er["pixel_error"]["v"]["rms_px"].get<double>() << " px; found in "
        << 100.0 * er["fraction_found"].get<double>() << " % of marker-frames in view; identity swaps "
        << er["identity_swaps"].get<int>() << ", stitched " << t.joins.size() << ", unresolved tracks "
        << t.unresolved.size() << "\n";
  }
  if (!calibration_report_.is_null())
    log << std::defaultfloat << std::setprecision(4) << "tracking camera calibrated from "
        << calibration_report_["photos"].get<int>() << " checkerboard photos: fx "
        << calibration_report_["fx_px"]["recovered"].get<double>() << " px (true "
        << calibration_report_["fx_px"]["true"].get<double>() << "), camera position off by "
        << 1e3 * calibration_report_["camera_position_error_m"].get<double>()
        << " mm, view direction by "
        << calibration_report_["view_direction_error_deg"].get<double>()
        << " deg, RMS reprojection " << calibration_report_["rms_reprojection_px"].get<double>()
        << " px\n";
  if (compared > 0) {
    s["rms_error_mps"] = std::sqrt(sum2 / compared);
    s["max_error_mps"] = max_abs;
    s["rms_error_pct"] = 100.0 * std::sqrt(sum2_rel / compared);
    s["max_error_pct"] = 100.0 * max_rel;
    PlotSpec plot;
    plot.title =
        "tracked (images only) against DEM truth, marker velocity over " + measureDistanceText();
    plot.x_label = "truth velocity (m/s)";
    plot.y_label = "tracked velocity (m/s)";
    double lo = *std::min_element(points.x.begin(), points.x.end()),
           hi = *std::max_element(points.x.begin(), points.x.end());
    plot.series = {points,
                   PlotSeries{"tracked = truth", {lo, hi}, {lo, hi}, PlotSeries::Style::Line}};
    writePlot(plot, out_dir / "tracked_vs_truth.png");
    log << std::defaultfloat << std::setprecision(3) << "tracking: " << tracked << " of "
        << markers_.size() << " markers tracked over " << e_.measure_distance * 1e3 << " mm in "
        << t.frames.size() << " frames; error against truth: RMS " << s["rms_error_mps"].get<double>()
        << " m/s (" << s["rms_error_pct"].get<double>() << " %), max " << max_abs << " m/s ("
        << 100.0 * max_rel << " %)\n";
    if (t.shape_fit) {
      log << "tracking: shape fit on " << t.shape_fit_counts.fitted << " detections ("
          << t.shape_fit_counts.searched << " searched, " << t.shape_fit_counts.unfitted
          << " left at the centroid, " << t.shape_fit_counts.duplicates
          << " withdrawn as another track's duplicate); the same tracks otherwise:";
      nlohmann::json variants = nlohmann::json::array();
      for (std::size_t d = 0; d < variant_errors.size(); ++d) {
        const Errors& e = variant_errors[d];
        if (e.compared == 0) continue;
        const double rms = 100.0 * std::sqrt(e.sum2_rel / e.compared);
        variants.push_back({{"variant", t.depth_variants[d].first},
                            {"markers_compared", e.compared},
                            {"rms_error_pct", rms},
                            {"max_error_pct", 100.0 * e.max_rel}});
        log << ' ' << t.depth_variants[d].first << " RMS " << rms << " %, max " << 100.0 * e.max_rel << " %;";
      }
      log << "\n";
      s["position_variants"] = variants;
    }
  } else {
    log << "tracking: no marker was tracked over the whole " << e_.measure_distance * 1e3
        << " mm\n";
  }
  return s;
}

void ChuteExperiment::report(nlohmann::json& r, const std::filesystem::path& out_dir,
                             std::ostream& log) {
  const bool flowed = std::isfinite(gate_time_);
  r["clearance_time_s"] = detail::finiteOrNull(clearance_time_);
  r["jammed"] = jammed_;
  nlohmann::json markers = nlohmann::json::array();
  for (const Marker& m : markers_)
    markers.push_back({{"id", m.id},
                       {"column", m.column},
                       {"row", m.row},
                       {"lab_position_m", {m.target.x(), m.target.y(), m.target.z()}},
                       {"start_position_m", {m.start.x(), m.start.y(), m.start.z()}},
                       {"onset_time_s", detail::finiteOrNull(m.onset_time)},
                       {"travel_time_s", detail::finiteOrNull(m.travel_time)},
                       {"truth_velocity_mps", detail::finiteOrNull(m.velocity)},
                       {"velocity_from_gate_mps", detail::finiteOrNull(m.velocity_from_gate)}});
  const nlohmann::json tracking = reportTracking(markers, out_dir, log);
  r["markers"] = markers;
  if (!tracking.is_null()) r["tracking"] = tracking;
  // Column profile: the mean truth velocity, and the mean tracked one when tracked.
  nlohmann::json profile = nlohmann::json::array();
  std::ostringstream profile_csv;  // written whole (detail::writeAtomically), as every table below
  profile_csv << "column,distance_m,mean_truth_velocity_mps,mean_tracked_velocity_mps\n";
  for (std::size_t c = 0; c < e_.marker_columns.size(); ++c) {
    double sum = 0, sum_tracked = 0;
    int n = 0, n_tracked = 0;
    for (std::size_t k = 0; k < markers_.size(); ++k) {
      if (markers_[k].column != static_cast<int>(c) + 1) continue;
      if (std::isfinite(markers_[k].velocity)) {
        sum += markers_[k].velocity;
        ++n;
      }
      const nlohmann::json& tv = markers[k].value("tracked_velocity_mps", nlohmann::json(nullptr));
      if (tv.is_number()) {
        sum_tracked += tv.get<double>();
        ++n_tracked;
      }
    }
    const nlohmann::json truth = n ? nlohmann::json(sum / n) : nlohmann::json(nullptr);
    const nlohmann::json tracked =
        n_tracked ? nlohmann::json(sum_tracked / n_tracked) : nlohmann::json(nullptr);
    profile.push_back({{"column", c + 1},
                       {"distance_m", e_.marker_columns[c]},
                       {"mean_truth_velocity_mps", truth},
                       {"markers_measured", n},
                       {"mean_tracked_velocity_mps", tracked},
                       {"markers_tracked", n_tracked}});
    profile_csv << c + 1 << ',' << e_.marker_columns[c] << ',' << (n ? std::to_string(sum / n) : "")
                << ',' << (n_tracked ? std::to_string(sum_tracked / n_tracked) : "") << '\n';
  }
  detail::writeAtomically(out_dir / "profile.csv", profile_csv.str());
  r["profile"] = profile;
  r["chute"] = {{"inclination_deg", e_.inclination_deg},
                {"gravity_tilt", e_.rotate_gravity ? "rotate" : "add"},
                {"deposit_inclination_deg", e_.deposit_inclination_deg},
                {"deposit_settled", settle_.settled()},
                {"deposit_end_s", detail::finiteOrNull(deposit_time_)},
                {"deposit_max_speed_mps", settle_.maxSpeed()},
                {"settle_scope", e_.top_wall.empty() ? "all" : e_.settle_scope},
                {"stop_after", e_.stop_after},
                {"stopped_after_deposit", stoppedAfterDeposit()},
                {"bed_height_m", bed_height_},
                {"bodies_removed_by_top_plate", removed_by_top_},
                {"bodies", bodies_total_},
                {"gate_open_s", detail::finiteOrNull(gate_time_)},
                {"discharged_bodies", discharged_count_},
                {"discharged_mass_kg", discharged_mass_},
                {"measure_distance_m", e_.measure_distance},
                {"marker_onset_m", kOnset},
                {"tilt_steps", e_.tilt_steps}};

  // CSV tables with units in the header, and the two plots.
  {
    std::ostringstream csv;
    csv << "id,column,row,start_x_m,start_y_m,start_z_m,onset_time_s,travel_time_s,truth_velocity_"
           "mps,"
           "velocity_from_gate_mps\n";
    for (const Marker& m : markers_)
      csv << m.id << ',' << m.column << ',' << m.row << ',' << m.start.x() << ',' << m.start.y()
          << ',' << m.start.z() << ',' << m.onset_time << ',' << m.travel_time << ',' << m.velocity
          << ',' << m.velocity_from_gate << '\n';
    detail::writeAtomically(out_dir / "markers.csv", csv.str());
    std::ostringstream d;
    d << "time_after_gate_s,discharged_mass_kg\n";
    for (const auto& [t, m] : discharge_curve_) d << t << ',' << m << '\n';
    detail::writeAtomically(out_dir / "discharge.csv", d.str());
  }
  if (flowed) {
    PlotSpec prof;
    prof.title = "marker velocity over the first " +
                 std::to_string(static_cast<int>(std::lround(e_.measure_distance * 1e3))) +
                 " mm (DEM truth), " +
                 std::to_string(static_cast<int>(std::lround(e_.inclination_deg))) + " deg";
    prof.x_label = "velocity along the base (m/s)";
    prof.y_label = "initial height above the base (mm)";
    for (std::size_t c = 0; c < e_.marker_columns.size(); ++c) {
      PlotSeries s;
      s.label = "column " + std::to_string(c + 1) + " (" +
                std::to_string(static_cast<int>(std::lround(e_.marker_columns[c] * 1e3))) + " mm)";
      std::vector<std::pair<double, double>> points;  // (height mm, velocity), drawn bottom up
      for (const Marker& m : markers_)
        if (m.column == static_cast<int>(c) + 1) points.emplace_back(m.start.z() * 1e3, m.velocity);
      std::sort(points.begin(), points.end());
      for (const auto& [z, v] : points) {
        s.x.push_back(v);
        s.y.push_back(z);
      }
      prof.series.push_back(s);
    }
    writePlot(prof, out_dir / "velocity_profile.png");
    // The column profile: DEM truth and, when the camera's frames were tracked, the tracker's.
    PlotSpec columns;
    columns.title = "column profile: mean marker velocity over " + measureDistanceText();
    columns.x_label = "column distance from the gate (mm)";
    columns.y_label = "mean velocity (m/s)";
    PlotSeries truth{"DEM truth", {}, {}, PlotSeries::Style::LinePoints};
    PlotSeries tracked{"tracked in the frames", {}, {}, PlotSeries::Style::LinePoints};
    for (const auto& c : r["profile"]) {
      const double x = c["distance_m"].get<double>() * 1e3;
      truth.x.push_back(x);
      truth.y.push_back(c["mean_truth_velocity_mps"].is_number()
                            ? c["mean_truth_velocity_mps"].get<double>()
                            : NAN);
      tracked.x.push_back(x);
      tracked.y.push_back(c["mean_tracked_velocity_mps"].is_number()
                              ? c["mean_tracked_velocity_mps"].get<double>()
                              : NAN);
    }
    columns.series = {truth};
    if (tracking_) columns.series.push_back(tracked);
    writePlot(columns, out_dir / "profile.png");
    PlotSpec dis;
    dis.title = "discharged mass after the gate opened";
    dis.x_label = "time after gate opening (s)";
    dis.y_label = "discharged mass (kg)";
    PlotSeries s{"discharged", {0.0}, {0.0}, PlotSeries::Style::Line};
    for (const auto& [t, m] : discharge_curve_) {
      s.x.push_back(t);
      s.y.push_back(m);
    }
    dis.series = {s};
    writePlot(dis, out_dir / "discharge.png");
  }

  log << std::setprecision(4) << "chute " << e_.inclination_deg << " deg: deposit ";
  if (std::isnan(deposit_time_))  // the run ended inside the deposit
    log << "unfinished (the run ended during it), " << bodies_total_ << " bodies";
  else
    log << (settle_.settled() ? "settled" : "NOT settled") << " at t = " << deposit_time_ << " s, bed "
        << bed_height_ * 1e3 << " mm, " << bodies_total_ << " bodies";
  if (removed_by_top_) log << " (" << removed_by_top_ << " bodies cut by the top plate removed)";
  log << "\n";
  if (stoppedAfterDeposit()) {
    log << "chute: stopped after the deposit (experiment.stop_after = \"deposit\"): restart from "
        << (out_dir / "checkpoint.h5").string()
        << " with each case's top plate (rocklab restart CHECKPOINT --set walls." << (e_.top_wall.empty() ? "NAME" : e_.top_wall)
        << ".angle_deg=..., or rocklab sweep CHECKPOINT --vary ...)\n";
    return;
  }
  if (!flowed) {
    log << "chute: the gate never opened (the run ended first: raise scene.end_time)\n";
    return;
  }
  log << "chute: "
      << (jammed_                          ? "JAMMED"
          : std::isfinite(clearance_time_) ? "cleared"
                                           : "still flowing at the end")
      << ", clearance time "
      << (std::isfinite(clearance_time_) ? std::to_string(clearance_time_) + " s" : "-")
      << ", discharged " << discharged_count_ << "/" << bodies_total_ << " bodies\n";
  for (const auto& c : profile)
    log << "  column " << c["column"] << " at " << c["distance_m"].get<double>() * 1e3
        << " mm: mean marker velocity " << c["mean_truth_velocity_mps"] << " m/s\n";
}

}  // namespace

std::unique_ptr<Experiment> makeChuteExperiment(const Scene& scene) {
  return std::make_unique<ChuteExperiment>(scene);
}

std::shared_ptr<ExperimentSettings> readChuteSettings(TableReader& t,
                                                      const SettingsContext& context) {
  auto settings = std::make_shared<ChuteSettings>();
  ChuteSettings& e = *settings;
  readSettleSettings(t, e.settle);
  e.calibration_photos = readCalibrationPhotos(t, e.calibration_photos);
  const Range positive = Range::positive();
  std::vector<std::string> names;
  for (const auto& w : context.model.walls) names.push_back(w.name);
  auto wallKey = [&](const std::string& key, const std::string& fallback) {
    return t.string(key, fallback, names);
  };
  e.length = t.number("length", e.length, positive);
  e.inclination_deg = t.number("inclination_deg", e.inclination_deg, Range::closed(0, 90));
  e.deposit_inclination_deg =
      t.number("deposit_inclination_deg", e.deposit_inclination_deg, Range::closed(0, 90));
  e.rotate_gravity = t.string("gravity_tilt", "rotate", {"rotate", "add"}) == "rotate";
  if (!e.rotate_gravity && (e.inclination_deg >= 90 || e.deposit_inclination_deg >= 90))
    t.fail("gravity_tilt", "\"add\" (g tan(angle) along the base) needs angles below 90 deg");
  e.gate_wall = wallKey("gate_wall", e.gate_wall);
  if (t.has("top_wall")) e.top_wall = wallKey("top_wall", "");
  e.settle_scope = t.string("settle_scope", e.settle_scope, {"kept", "all"});
  e.stop_after = t.string("stop_after", e.stop_after, {"none", "deposit"});
  if (e.stop_after != "none") e.needs_checkpoint = "stop_after";
  e.temporary_walls = t.stringList("temporary_walls", names);
  e.tilt_steps = static_cast<std::uint64_t>(
      t.integer("tilt_steps", static_cast<std::int64_t>(e.tilt_steps), Range::nonNegative()));
  e.marker_columns = t.numberList("marker_columns", Range::nonNegative());
  e.marker_heights = t.numberList("marker_heights", Range::nonNegative());
  e.marker_height_fractions = t.numberList("marker_height_fractions", Range::closed(0, 1));
  if (!e.marker_heights.empty() && !e.marker_height_fractions.empty())
    t.fail("marker_height_fractions",
           "give marker_heights (m) or marker_height_fractions, not both");
  e.marker_y = t.number("marker_y", e.marker_y, Range::nonNegative());
  e.measure_distance = t.number("measure_distance", e.measure_distance, positive);
  e.remove_beyond = t.number("remove_beyond", e.remove_beyond, positive);
  e.jam_time = t.number("jam_time", e.jam_time, positive);
  e.track = t.boolean("track", e.track);
  std::vector<std::string> camera_names;
  for (const auto& c : context.cameras) camera_names.push_back(c.name);
  e.track_camera =
      t.string("track_camera", camera_names.empty() ? "" : camera_names.front(), camera_names);
  if (!e.track) e.track_camera.clear();
  e.track_position = t.string("track_position", e.track_position, {"shape", "centroid"});
  return settings;
}

}  // namespace rocklab::experiments
