// Heap test (experiments.md §b): the poured pebbles come to rest on the table;
// the angle of repose is measured from the final positions (heap_analysis.h).
#include "drivers/heap_experiment.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <ostream>

#include "analysis/heap_analysis.h"
#include "analysis/plot.h"
#include "camera/camera_calibration.h"
#include "camera/camera_recorder.h"
#include "common/json_text.h"
#include "drivers/settle.h"
#include "rocklab/render/image_io.h"
#include "rocklab/track/plane.h"

namespace rocklab::experiments {

namespace {

class HeapExperiment final : public Experiment {
 public:
  explicit HeapExperiment(const Scene& scene)
      : e_(settingsOf<HeapSettings>(scene)), settle_(e_.settle) {
    if (!scene.cameras.empty()) camera_ = scene.cameras.front();
  }

  // The photograph: the camera's last raw frame before the heap is measured.
  std::string trackingCamera() const override {
    return balls_.empty() ? camera_.name : std::string();
  }
  void cameraFrame(std::uint64_t, double, const cv::Mat& raw) override { photo_ = raw.clone(); }

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext&) override {
    const std::uint64_t every = stepsIn(e_.sample_interval, world->dt());
    if (world->stepCount() % every != 0) return true;
    const double t = world->time();
    if (!settle_.over(*world)) return true;
    settle_time_ = t;
    const auto& p = world->particles();
    balls_.clear();
    for (std::size_t i = 0; i < p.size(); ++i) balls_.push_back({p.position[i], p.radius[i]});
    return false;
  }

  std::string progress() const override {
    return "max speed " + std::to_string(settle_.maxSpeed()).substr(0, 6) + " m/s (settled below " +
           std::to_string(e_.settle.speed).substr(0, 6) + ")";
  }

  void report(nlohmann::json& r, const std::filesystem::path& out_dir, std::ostream& log) override {
    nlohmann::json h;
    h["settled"] = settle_.settled();
    h["max_speed_mps"] = settle_.maxSpeed();
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
      log << "), height " << a.height_m << " m"
          << (settle_.settled() ? "" : " — NOT settled (settle_max_time reached)") << "\n";
    } catch (const std::exception& ex) {
      r["angle_of_repose_deg"] = nullptr;
      h["note"] = std::string("no heap to measure: ") + ex.what();
      log << "heap: no angle: " << ex.what() << "\n";
    }
    if (!photo_.empty()) h["photograph"] = measurePhoto(out_dir, r["angle_of_repose_deg"], log);
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

  /// The angle as a lab reads it off a side photograph: pebble pixels (brighter
  /// than the dark table and backdrop), the top of the pile in every pixel column,
  /// pixels mapped onto the vertical plane through the heap axis, and a line fit
  /// on each flank between 20 % and 80 % of the height.
  nlohmann::json measurePhoto(const std::filesystem::path& out_dir, const nlohmann::json& geometric,
                              std::ostream& log) const {
    render::writePng(out_dir / "heap_side.png", photo_);
    double cx = 0, cy = 0;
    for (const auto& b : balls_) {
      cx += b.centre.x() / static_cast<double>(balls_.size());
      cy += b.centre.y() / static_cast<double>(balls_.size());
    }
    // The lab calibrates its camera with a board held in that plane (facing the
    // camera), or trusts the renderer's camera when calibration_photos = 0.
    const geometry::Vec3 axis_point(cx, cy, e_.base_z);
    const geometry::Vec3 towards_camera(0.0, camera_.camera.position().y() > cy ? 1.0 : -1.0, 0.0);
    nlohmann::json calibration;
    geometry::Camera camera = camera_.camera;
    if (e_.calibration_photos > 0) {
      try {
        const WallCalibration cal =
            calibrateOnWall(camera_.camera, renderOptionsFor(camera_), axis_point, towards_camera,
                            e_.calibration_photos);
        camera = cal.camera;
        calibration = cal.report;
      } catch (
          const std::exception& e) {  // no calibrated camera: no photograph angle, the rest stands
        log << "heap: no angle from the photograph (camera calibration failed: " << e.what()
            << ")\n";
        return {{"file", "heap_side.png"},
                {"error", std::string("camera calibration failed: ") + e.what()}};
      }
    }
    std::vector<double> xs, zs;
    for (int u = 0; u < photo_.cols; ++u)
      for (int v = 2; v < photo_.rows; ++v) {
        auto bright = [&](int row) {
          const cv::Vec3b p = photo_.at<cv::Vec3b>(row, u);
          return std::max({p[0], p[1], p[2]}) > 70;
        };
        if (!(bright(v) && bright(v - 1) && bright(v - 2)))
          continue;  // three in a row: not a speck
        if (const auto w =
                track::pixelToPlane(camera, cv::Point2d(u, v - 2), axis_point, towards_camera)) {
          if (w->z() > e_.base_z + 0.005) {
            xs.push_back(w->x() - cx);
            zs.push_back(w->z() - e_.base_z);
          }
        }
        break;
      }
    nlohmann::json out;
    if (xs.size() < 10) {
      out["note"] = "no pile found in the photograph";
      return out;
    }
    const std::size_t peak =
        static_cast<std::size_t>(std::max_element(zs.begin(), zs.end()) - zs.begin());
    const double height = zs[peak];
    std::vector<double> angles;
    for (int side : {-1, 1}) {
      double sx = 0, sz = 0, sxx = 0, sxz = 0;
      int n = 0;
      for (std::size_t k = 0; k < xs.size(); ++k) {
        if ((xs[k] - xs[peak]) * side <= 0 || zs[k] < 0.2 * height || zs[k] > 0.8 * height)
          continue;
        sx += xs[k];
        sz += zs[k];
        sxx += xs[k] * xs[k];
        sxz += xs[k] * zs[k];
        ++n;
      }
      const double den = n * sxx - sx * sx;
      angles.push_back(n >= 3 && den > 0 ? std::atan(std::abs((n * sxz - sx * sz) / den)) * 180.0 /
                                               std::numbers::pi
                                         : std::numeric_limits<double>::quiet_NaN());
    }
    const double mean = 0.5 * (angles[0] + angles[1]);
    out = {{"file", "heap_side.png"},
           {"flank_angles_deg", {angles[0], angles[1]}},
           {"angle_deg", detail::finiteOrNull(mean)},
           {"height_m", height},
           {"calibration", calibration},
           {"method",
            "side photograph: top of the pile per pixel column, mapped onto the vertical plane "
            "through "
            "the heap axis, least-squares line per flank between 20 % and 80 % of the height"}};
    if (std::isfinite(mean) && geometric.is_number())
      out["difference_to_geometric_deg"] = mean - geometric.get<double>();
    log << "heap: from the side photograph " << mean << " deg (flanks " << angles[0] << ", "
        << angles[1] << ")\n";
    return out;
  }

  HeapSettings e_;
  CameraSettings camera_;  // the first camera: it takes the photograph
  cv::Mat photo_;
  SettleDetector settle_;
  double settle_time_ = 0;
  std::vector<geometry::Sphere> balls_;
};

}  // namespace

std::unique_ptr<Experiment> makeHeapExperiment(const Scene& scene) {
  return std::make_unique<HeapExperiment>(scene);
}

std::shared_ptr<ExperimentSettings> readHeapSettings(TableReader& t,
                                                     const SettingsContext& /*context*/) {
  auto e = std::make_shared<HeapSettings>();
  readSettleSettings(t, e->settle);
  e->calibration_photos = readCalibrationPhotos(t, e->calibration_photos);
  e->base_z = t.number("base_z", e->base_z);
  e->bin_width = t.number("bin_width", e->bin_width, Range::positive());
  return e;
}

}  // namespace rocklab::experiments
