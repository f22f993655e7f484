// Product photograph: the particles settle on the tray (drivers/settle.h), the
// first camera's last frame before that is the photograph, and the report sets
// its image-based sizes (track::sizeParticles, which sees only the image and the
// camera) beside the settled particles' true diameters.
#include "drivers/product_photo_experiment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <ostream>
#include <sstream>

#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "crusher/product_statistics.h"
#include "drivers/settle.h"
#include "rocklab/render/image_io.h"

namespace rocklab::experiments {

namespace {

using crusher::ProductBall;

struct TrueBall {
  geometry::Vec3 centre;
  double radius = 0;  // m
  double mass = 0;    // kg
};

class ProductPhotoExperiment final : public Experiment {
 public:
  explicit ProductPhotoExperiment(const Scene& scene)
      : e_(settingsOf<ProductPhotoSettings>(scene)), settle_(e_.settle), camera_(scene.cameras.front()) {}

  // The photograph: the camera's last frame before the particles are at rest.
  std::string trackingCamera() const override { return balls_.empty() ? camera_.name : std::string(); }
  void cameraFrame(std::uint64_t, double time, const cv::Mat& raw) override {
    photo_ = raw.clone();
    photo_time_ = time;
  }

  bool advance(std::unique_ptr<sim::World>& world, const ExperimentContext&) override {
    if (world->stepCount() % stepsIn(e_.sample_interval, world->dt()) != 0) return true;
    if (!settle_.over(*world)) return true;
    settle_time_ = world->time();
    const auto& p = world->particles();
    for (std::size_t i = 0; i < p.size(); ++i) balls_.push_back({p.position[i], p.radius[i], p.mass[i]});
    return false;
  }

  std::string progress() const override {
    return "max speed " + std::to_string(settle_.maxSpeed()).substr(0, 6) + " m/s (at rest below " +
           std::to_string(e_.settle.speed).substr(0, 6) + ")";
  }

  void report(nlohmann::json& r, const std::filesystem::path& out_dir, std::ostream& log) override {
    nlohmann::json s;
    s["settled"] = settle_.settled();
    s["max_speed_mps"] = settle_.maxSpeed();
    if (balls_.empty() || photo_.empty()) {
      s["note"] = balls_.empty() ? "the run ended before the particles came to rest (raise scene.end_time)"
                                 : "no photograph: the camera rendered no frame before the particles came to rest";
      r["product_photo"] = s;
      log << "product photo: not measured (" << s["note"].get<std::string>() << ")\n";
      return;
    }
    s["settle_time_s"] = settle_time_;
    s["photo_time_s"] = photo_time_;
    render::writePng(out_dir / "product_photo.png", photo_);
    const geometry::Camera& camera = camera_.camera;
    const track::SizingResult sized =
        track::sizeParticles(photo_, camera, geometry::Vec3(0, 0, e_.surface_z), geometry::Vec3::UnitZ(), e_.sizing);

    // Which true balls each image particle holds: the label at each ball's projected centre.
    std::map<int, std::size_t> particle_of_label;
    for (std::size_t k = 0; k < sized.particles.size(); ++k) particle_of_label[sized.particles[k].label] = k;
    std::vector<std::vector<std::size_t>> members(sized.particles.size());
    int out_of_view = 0, missed = 0;
    std::vector<ProductBall> truth, image_equivalent, image_feret;
    for (std::size_t i = 0; i < balls_.size(); ++i) {
      const bool in_front = camera.toCamera(balls_[i].centre).z() > 0;
      const geometry::Vec2 px = in_front ? camera.project(balls_[i].centre) : geometry::Vec2(-1, -1);
      const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
      if (u < 0 || v < 0 || u >= photo_.cols || v >= photo_.rows) {
        ++out_of_view;
        continue;
      }
      truth.push_back({0, 0, 2 * balls_[i].radius, balls_[i].mass});
      const auto found = particle_of_label.find(sized.labels.at<int>(v, u));
      if (found == particle_of_label.end()) {
        ++missed;
        continue;
      }
      members[found->second].push_back(i);
    }
    // Per particle: one ball = matched; none = spurious; more = merged with or hiding others.
    int matched = 0, spurious = 0, merged = 0, hidden_balls = 0, on_border = 0;
    double sum_error = 0, sum2_error = 0, max_error = 0;
    std::ostringstream csv;
    csv << "label,u_px,v_px,area_px,equivalent_diameter_mm,feret_max_mm,feret_min_mm,on_border,true_balls,"
           "true_diameter_mm\n";
    // An image particle's mass: a sphere of its equivalent diameter at the balls' density.
    const double density =
        balls_.front().mass / (4.0 / 3.0 * std::numbers::pi * std::pow(balls_.front().radius, 3));
    const auto mass = [&](double d) { return density * std::numbers::pi * d * d * d / 6.0; };
    for (std::size_t k = 0; k < sized.particles.size(); ++k) {
      const track::SizedParticle& p = sized.particles[k];
      image_equivalent.push_back({0, 0, p.equivalent_diameter_m, mass(p.equivalent_diameter_m)});
      image_feret.push_back({0, 0, p.feret_min_m, mass(p.equivalent_diameter_m)});
      on_border += p.on_border ? 1 : 0;
      const std::vector<std::size_t>& in = members[k];
      double true_d = std::numeric_limits<double>::quiet_NaN();
      if (in.empty()) {
        ++spurious;
      } else if (in.size() == 1) {
        ++matched;
        true_d = 2 * balls_[in[0]].radius;
        const double e = p.equivalent_diameter_m / true_d - 1.0;
        sum_error += e;
        sum2_error += e * e;
        max_error = std::max(max_error, std::abs(e));
      } else {
        ++merged;
        hidden_balls += static_cast<int>(in.size()) - 1;
      }
      csv << p.label << ',' << p.centre_px.x << ',' << p.centre_px.y << ',' << p.area_px << ','
          << 1e3 * p.equivalent_diameter_m << ',' << 1e3 * p.feret_max_m << ',' << 1e3 * p.feret_min_m << ','
          << (p.on_border ? 1 : 0) << ',' << in.size() << ',';
      if (std::isfinite(true_d)) csv << 1e3 * true_d;
      csv << '\n';
    }
    detail::writeAtomically(out_dir / "product_particles.csv", csv.str());

    const std::vector<double> truth_passing = crusher::massPassing(truth, e_.sieves_mm),
                              image_passing = crusher::massPassing(image_equivalent, e_.sieves_mm),
                              feret_passing = crusher::massPassing(image_feret, e_.sieves_mm);
    nlohmann::json psd = nlohmann::json::array();
    double worst_class = 0;
    for (std::size_t k = 0; k < e_.sieves_mm.size(); ++k) {
      psd.push_back({{"size_mm", e_.sieves_mm[k]},
                     {"passing_truth", truth_passing[k]},
                     {"passing_image", image_passing[k]},
                     {"passing_image_feret_min", feret_passing[k]},
                     {"error_points", 100 * (image_passing[k] - truth_passing[k])}});
      worst_class = std::max(worst_class, std::abs(image_passing[k] - truth_passing[k]));
    }
    s["psd"] = psd;
    for (const auto& [key, fraction] : {std::pair{"p50_mm", 0.5}, std::pair{"p80_mm", 0.8}})
      s[key] = {{"truth", crusher::sizeAtPassingMm(truth, fraction)},
                {"image", crusher::sizeAtPassingMm(image_equivalent, fraction)},
                {"image_feret_min", crusher::sizeAtPassingMm(image_feret, fraction)}};
    s["max_passing_error_points"] = 100 * worst_class;
    s["particles"] = {{"true_in_view", truth.size()}, {"out_of_view", out_of_view}, {"found", sized.particles.size()},
                      {"matched", matched}, {"merged", merged}, {"balls_hidden_or_merged", hidden_balls},
                      {"missed", missed}, {"spurious", spurious}, {"on_border", on_border}};
    s["matched_diameter_error"] = {
        {"mean_pct", matched ? 100 * sum_error / matched : 0.0},
        {"rms_pct", matched ? 100 * std::sqrt(sum2_error / matched) : 0.0},
        {"max_pct", 100 * max_error}};
    s["threshold_grey"] = sized.threshold;
    s["camera"] = camera_.name;
    s["method"] =
        "image: pixels brighter than the tray (Otsu), touching particles split at distance-transform peaks, each "
        "particle's area and Feret diameters on the plane half its size above the tray (renderer's exact camera); "
        "mass of an image particle from its equivalent diameter as a sphere at the particles' density; truth: the "
        "settled balls whose centres are in view; matched = one true ball's centre in the particle";
    r["product_photo"] = s;
    r["p50_mm"] = s["p50_mm"]["image"];
    r["p80_mm"] = s["p80_mm"]["image"];
    writeOverlay(out_dir / "product_sizing.png", sized, members);
    writeCurves(out_dir / "product_psd.png", truth_passing, image_passing, feret_passing, log);
    log << "product photo: " << sized.particles.size() << " particles found for " << truth.size()
        << " in view (matched " << matched << ", merged " << merged << ", missed " << missed << ", spurious "
        << spurious << "); matched diameters off by " << s["matched_diameter_error"]["mean_pct"].get<double>()
        << " % on average (RMS " << s["matched_diameter_error"]["rms_pct"].get<double>()
        << " %); P50 " << s["p50_mm"]["image"] << " mm from the image against " << s["p50_mm"]["truth"]
        << " mm; passing off by at most " << 100 * worst_class << " points\n";
  }

 private:
  /// The photograph with each particle's outline: green one true ball, orange
  /// several (merged or hiding others), red none.
  void writeOverlay(const std::filesystem::path& png, const track::SizingResult& sized,
                    const std::vector<std::vector<std::size_t>>& members) const {
    std::map<int, cv::Vec3b> colour_of;
    for (std::size_t k = 0; k < sized.particles.size(); ++k)
      colour_of[sized.particles[k].label] = members[k].empty()     ? cv::Vec3b(40, 40, 230)
                                            : members[k].size() == 1 ? cv::Vec3b(60, 200, 60)
                                                                     : cv::Vec3b(0, 150, 255);
    cv::Mat out = photo_.clone();
    const cv::Mat& labels = sized.labels;
    for (int v = 0; v < labels.rows; ++v)
      for (int u = 0; u < labels.cols; ++u) {
        const int l = labels.at<int>(v, u);
        if (l == 0) continue;
        const bool edge = (u > 0 && labels.at<int>(v, u - 1) != l) || (u + 1 < labels.cols && labels.at<int>(v, u + 1) != l) ||
                          (v > 0 && labels.at<int>(v - 1, u) != l) || (v + 1 < labels.rows && labels.at<int>(v + 1, u) != l);
        if (!edge) continue;
        const auto c = colour_of.find(l);
        if (c != colour_of.end()) out.at<cv::Vec3b>(v, u) = c->second;
      }
    render::writePng(png, out);
  }

  void writeCurves(const std::filesystem::path& png, const std::vector<double>& truth,
                   const std::vector<double>& image, const std::vector<double>& feret, std::ostream& log) const {
    PlotSpec spec = sieveChart("Product size from the photograph against the truth");
    const auto percent = [](std::vector<double> v) {
      for (double& x : v) x *= 100;
      return v;
    };
    spec.series = {PlotSeries{"truth (settled balls in view)", e_.sieves_mm, percent(truth)},
                   PlotSeries{"image, equivalent diameter", e_.sieves_mm, percent(image)},
                   PlotSeries{"image, smallest Feret diameter", e_.sieves_mm, percent(feret)}};
    try {
      writePlot(spec, png);
    } catch (const std::exception& ex) {
      log << "product photo: no size plot (" << ex.what() << ")\n";
    }
  }

  ProductPhotoSettings e_;
  SettleDetector settle_;
  CameraSettings camera_;
  cv::Mat photo_;
  double photo_time_ = 0, settle_time_ = 0;
  std::vector<TrueBall> balls_;
};

}  // namespace

std::unique_ptr<Experiment> makeProductPhotoExperiment(const Scene& scene) {
  return std::make_unique<ProductPhotoExperiment>(scene);
}

std::shared_ptr<ExperimentSettings> readProductPhotoSettings(TableReader& t, const SettingsContext& context) {
  if (context.cameras.empty())
    t.fail("type", "\"product_photo\" needs a [[cameras]] table: its first camera photographs the tray from above");
  auto e = std::make_shared<ProductPhotoSettings>();
  readSettleSettings(t, e->settle);
  e->surface_z = t.number("surface_z", e->surface_z);
  if (t.has("sieves_mm")) {
    e->sieves_mm = t.numberList("sieves_mm", Range::positive());
    if (e->sieves_mm.empty() || !std::is_sorted(e->sieves_mm.begin(), e->sieves_mm.end()))
      t.fail("sieves_mm", "must be a non-empty list of sizes in increasing order (mm)");
  }
  e->sizing.threshold = t.number("threshold", e->sizing.threshold);
  if (!(e->sizing.threshold < 256)) t.fail("threshold", "must be a grey level below 256 (< 0: Otsu's)");
  e->sizing.outline_iterations =
      static_cast<int>(t.integer("outline_iterations", e->sizing.outline_iterations, Range::closed(0, 20)));
  return e;
}

}  // namespace rocklab::experiments
