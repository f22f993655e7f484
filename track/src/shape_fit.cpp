#include "rocklab/track/shape_fit.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include <unsupported/Eigen/NonLinearOptimization>

namespace rocklab::track {

namespace {

using geometry::Vec3;

[[noreturn]] void invalid(const std::string& field, const std::string& what, double got) {
  std::ostringstream s;
  s << field << ' ' << what << " (got " << got << ')';
  throw std::invalid_argument(s.str());
}

// The silhouette of one ball in the image: an ellipse (pixel centre, unit radial
// direction, semi-axes along it and across it).
struct Ellipse {
  cv::Point2d centre;
  cv::Point2d radial;
  double along = 0, across = 0;  // px
  double inv_along2 = 0, inv_across2 = 0;  // 1 / along², 1 / across²
};

// The exact perspective silhouette of a sphere (camera-frame centre p, radius r):
// the cone of half-angle asin(r/|p|) about p cut by the image plane z = 1 is an
// ellipse centred off the projected centre, long along the radial direction
// (1/cos²θ against 1/cosθ across); distortion is applied at its centre, its local
// radial and tangential stretch scale the axes. False when the camera is inside
// the sphere or the silhouette reaches behind the image plane.
bool silhouette(const geometry::Camera& camera, const Vec3& p, double r, Ellipse& out) {
  const double d2 = p.squaredNorm();
  if (!(d2 > r * r) || !(p.z() > 0)) return false;
  const double d = std::sqrt(d2);
  const double sin_a = r / d, cos_a = std::sqrt(1.0 - sin_a * sin_a), tan_a = sin_a / cos_a;
  const double off_axis = std::sqrt(p.x() * p.x() + p.y() * p.y());
  const double tan_t = off_axis / p.z(), sin_t = off_axis / d, cos_t = p.z() / d;
  // tan(θ ± α) without trigonometric calls (this runs for every ball at every step).
  if (!(tan_t * tan_a < 1.0 - 1e-9)) return false;  // the silhouette reaches behind the image plane
  out.radial = off_axis > 1e-12 * d ? cv::Point2d(p.x() / off_axis, p.y() / off_axis) : cv::Point2d(1, 0);
  const double far = (tan_t + tan_a) / (1.0 - tan_t * tan_a), near = (tan_t - tan_a) / (1.0 + tan_t * tan_a);
  const double m = 0.5 * (far + near), a = 0.5 * (far - near);
  const double lift = m * sin_t + cos_t;
  const double b = std::sqrt(std::max(lift * lift / (cos_a * cos_a) - m * m - 1.0, 1e-18));
  const double r2 = m * m;
  const double stretch = 1.0 + camera.k1 * r2 + camera.k2 * r2 * r2;             // tangential
  const double radial_stretch = 1.0 + 3.0 * camera.k1 * r2 + 5.0 * camera.k2 * r2 * r2;  // d(s r)/dr
  const double f = 0.5 * (camera.fx + camera.fy);
  out.centre = {camera.fx * stretch * m * out.radial.x + camera.cx, camera.fy * stretch * m * out.radial.y + camera.cy};
  out.along = f * a * radial_stretch;
  out.across = f * b * stretch;
  if (!(out.along > 0 && out.across > 0)) return false;
  out.inv_along2 = 1.0 / (out.along * out.along);
  out.inv_across2 = 1.0 / (out.across * out.across);
  return true;
}

// Signed distance of an edge point from the ellipse, along the ray from its centre
// (exact on the axes; a circle's signed distance when along = across). Square
// roots only: this is the inner loop of every fit.
double distanceTo(const Ellipse& e, cv::Point2d point) {
  const double dx = point.x - e.centre.x, dy = point.y - e.centre.y;
  const double vr = dx * e.radial.x + dy * e.radial.y, vt = dy * e.radial.x - dx * e.radial.y;
  const double length2 = vr * vr + vt * vt;
  const double q2 = vr * vr * e.inv_along2 + vt * vt * e.inv_across2;
  if (q2 < 1e-24) return -std::min(e.along, e.across);
  const double length = std::sqrt(length2);
  return length - length / std::sqrt(q2);
}

// Huber's loss as a least-squares residual: r² = 2δ|d| − δ² beyond δ.
double huber(double d, double delta) {
  const double a = std::abs(d);
  if (a <= delta) return d;
  return std::copysign(std::sqrt(2.0 * delta * a - delta * delta), d);
}

// Eigen's LM functor: 5 parameters (mm along the wall's two directions, a
// rotation vector in rad applied before the start orientation), one residual per
// edge point.
struct OutlineResiduals {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  const ShapeFitter* fitter = nullptr;
  const geometry::Camera* camera = nullptr;
  const std::vector<cv::Point2f>* edges = nullptr;
  Eigen::Quaterniond start_orientation;
  double start_u = 0, start_v = 0;  // m along the wall
  Vec3 along_u, along_v;
  double robust_px = 1.0;

  int inputs() const { return 5; }
  int values() const { return static_cast<int>(edges->size()); }

  Eigen::Quaterniond orientation(const Eigen::VectorXd& x) const {
    const Vec3 w(x[2], x[3], x[4]);
    const double angle = w.norm();
    if (!(angle > 0)) return start_orientation;
    return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle)) * start_orientation).normalized();
  }
  Vec3 centre(const Eigen::VectorXd& x, const Eigen::Quaterniond& q) const {
    const MarkerModel& model = fitter->model();
    return model.wall_point + (start_u + 1e-3 * x[0]) * along_u + (start_v + 1e-3 * x[1]) * along_v +
           fitter->wallDistance(q) * model.wall_normal.normalized();
  }

  // The balls' silhouettes at parameters x; false when one is not in front of the camera.
  bool outlineAt(const Eigen::VectorXd& x, std::vector<Ellipse>& outline) const {
    const Eigen::Quaterniond q = orientation(x);
    const Vec3 c = centre(x, q);
    const std::vector<geometry::Sphere>& balls = fitter->model().balls;
    outline.resize(balls.size());
    for (std::size_t k = 0; k < balls.size(); ++k)
      if (!silhouette(*camera, camera->toCamera(c + q * balls[k].centre), balls[k].radius, outline[k])) return false;
    return true;
  }

  // Residuals, and (when `nearest_ball` is given) which ball's silhouette each edge
  // point is nearest.
  int evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& residuals, std::vector<std::uint8_t>* nearest_ball) const {
    thread_local std::vector<Ellipse> outline;
    const bool seen = outlineAt(x, outline);
    if (nearest_ball) nearest_ball->assign(edges->size(), 0);
    for (std::size_t i = 0; i < edges->size(); ++i) {
      if (!seen) {  // behind the camera: as bad as it gets, and flat (LM backs off)
        residuals[static_cast<Eigen::Index>(i)] = 1e3;
        continue;
      }
      const cv::Point2d e((*edges)[i].x, (*edges)[i].y);
      double nearest = std::numeric_limits<double>::infinity();
      std::size_t which = 0;
      for (std::size_t k = 0; k < outline.size(); ++k)
        if (const double d = distanceTo(outline[k], e); d < nearest) nearest = d, which = k;
      if (nearest_ball) (*nearest_ball)[i] = static_cast<std::uint8_t>(which);
      residuals[static_cast<Eigen::Index>(i)] = huber(nearest, robust_px);
    }
    return 0;
  }

  // The last evaluation: LM asks for the Jacobian where it last evaluated.
  mutable Eigen::VectorXd last_x, last_residuals;
  mutable std::vector<std::uint8_t> last_nearest;

  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& residuals) const {
    evaluate(x, residuals, &last_nearest);
    last_x = x;
    last_residuals = residuals;
    return 0;
  }

  // Forward differences with each edge point kept on its nearest ball (the min over
  // the balls is differentiable almost everywhere, and this way a step costs one
  // silhouette per edge point instead of one per ball).
  int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jacobian) const {
    thread_local std::vector<Ellipse> outline;
    if (last_x.size() != x.size() || last_x != x) {
      last_residuals.resize(static_cast<Eigen::Index>(edges->size()));
      evaluate(x, last_residuals, &last_nearest);
      last_x = x;
    }
    const Eigen::VectorXd& base = last_residuals;
    const std::vector<std::uint8_t>& nearest_ball = last_nearest;
    constexpr double kStep = 1e-6;  // mm and rad
    for (Eigen::Index j = 0; j < 5; ++j) {
      Eigen::VectorXd stepped = x;
      stepped[j] += kStep;
      const bool seen = outlineAt(stepped, outline);
      for (std::size_t i = 0; i < edges->size(); ++i) {
        const auto row = static_cast<Eigen::Index>(i);
        if (!seen) {
          jacobian(row, j) = 0.0;
          continue;
        }
        const double d = distanceTo(outline[nearest_ball[i]], cv::Point2d((*edges)[i].x, (*edges)[i].y));
        jacobian(row, j) = (huber(d, robust_px) - base[row]) / kStep;
      }
    }
    return 0;
  }
};

// Evenly spread orientations: body z turned to the points of a Fibonacci sphere,
// each with `turns` rotations about that axis.
std::vector<Eigen::Quaterniond> spreadOrientations(int count) {
  const int turns = 4;
  const int axes = std::max(1, (count + turns - 1) / turns);
  std::vector<Eigen::Quaterniond> out;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < axes && static_cast<int>(out.size()) < count; ++i) {
    const double z = 1.0 - (i + 0.5) * 2.0 / axes;
    const double ring = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 axis(ring * std::cos(golden * i), ring * std::sin(golden * i), z);
    const Eigen::Quaterniond tilt = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis);
    for (int j = 0; j < turns && static_cast<int>(out.size()) < count; ++j)
      out.push_back(tilt * Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * std::numbers::pi * j / turns, Vec3::UnitZ())));
  }
  return out;
}

}  // namespace

void MarkerModel::validate() const {
  if (balls.empty()) invalid("marker_model.balls", "must hold at least one ball", 0);
  for (const geometry::Sphere& b : balls)
    if (!(b.radius > 0) || !b.centre.allFinite()) invalid("marker_model.balls", "need finite centres and radii > 0 m", b.radius);
  if (!wall_point.allFinite()) invalid("marker_model.wall_point", "must be finite", wall_point.norm());
  if (!(wall_normal.norm() > 0) || !wall_normal.allFinite())
    invalid("marker_model.wall_normal", "must be a finite non-zero vector", wall_normal.norm());
}

void ShapeFitSettings::validate() const {
  if (start_orientations < 1 || start_orientations > 10000)
    invalid("shape_fit.start_orientations", "must be in [1, 10000]", start_orientations);
  if (refined_starts < 1 || refined_starts > start_orientations)
    invalid("shape_fit.refined_starts", "must be in [1, start_orientations]", refined_starts);
  if (!(reseed_rms_px > 0) || !std::isfinite(reseed_rms_px)) invalid("shape_fit.reseed_rms_px", "must be > 0 px", reseed_rms_px);
  if (!(reseed_ratio >= 1) || !std::isfinite(reseed_ratio)) invalid("shape_fit.reseed_ratio", "must be >= 1", reseed_ratio);
  if (!(robust_px > 0) || !std::isfinite(robust_px)) invalid("shape_fit.robust_px", "must be > 0 px", robust_px);
  if (max_evaluations < 10) invalid("shape_fit.max_evaluations", "must be >= 10", max_evaluations);
  if (min_edge_points < 5) invalid("shape_fit.min_edge_points", "must be >= 5 (one per parameter)", min_edge_points);
  if (max_edge_points < min_edge_points) invalid("shape_fit.max_edge_points", "must be >= min_edge_points", max_edge_points);
}

ShapeFitter::ShapeFitter(const geometry::Camera& camera, MarkerModel model, ShapeFitSettings settings)
    : camera_(camera), model_(std::move(model)), settings_(settings) {
  camera_.validate();
  model_.validate();
  settings_.validate();
  const Vec3 n = model_.wall_normal.normalized();
  model_.wall_normal = n;
  // Any two unit vectors spanning the wall.
  const Vec3 helper = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  along_u_ = (helper - helper.dot(n) * n).normalized();
  along_v_ = n.cross(along_u_);
  starts_ = spreadOrientations(settings_.start_orientations);
}

double ShapeFitter::wallDistance(const Eigen::Quaterniond& orientation) const {
  double h = -std::numeric_limits<double>::infinity();
  for (const geometry::Sphere& b : model_.balls)
    h = std::max(h, b.radius - model_.wall_normal.dot(orientation * b.centre));
  return h;
}

std::optional<MarkerPose> ShapeFitter::poseThrough(const Eigen::Quaterniond& orientation, cv::Point2d pixel) const {
  Vec3 ray;
  try {
    ray = camera_.pixelRay(geometry::Vec2(pixel.x, pixel.y));
  } catch (const std::domain_error&) {
    return std::nullopt;  // the lens folds over there
  }
  // The centre lies on the plane parallel to the wall at h(R) from it.
  const Vec3 eye = camera_.position();
  const double along = ray.dot(model_.wall_normal);
  if (std::abs(along) < 1e-12) return std::nullopt;
  const double s = (model_.wall_point - eye).dot(model_.wall_normal) + wallDistance(orientation);
  if (!(s / along > 0)) return std::nullopt;
  MarkerPose pose;
  pose.orientation = orientation;
  pose.centre = eye + (s / along) * ray;
  pose.pixel = pixel;
  return pose;
}

MarkerPose ShapeFitter::refine(const std::vector<cv::Point2f>& edges, const MarkerPose& start) const {
  OutlineResiduals residuals;
  residuals.fitter = this;
  residuals.camera = &camera_;
  residuals.edges = &edges;
  residuals.start_orientation = start.orientation;
  residuals.start_u = along_u_.dot(start.centre - model_.wall_point);
  residuals.start_v = along_v_.dot(start.centre - model_.wall_point);
  residuals.along_u = along_u_;
  residuals.along_v = along_v_;
  residuals.robust_px = settings_.robust_px;
  Eigen::LevenbergMarquardt<OutlineResiduals> lm(residuals);
  lm.parameters.maxfev = settings_.max_evaluations;
  // Parameters in mm and rad: 1e-6 of their scaled norm is far below the edges' noise.
  lm.parameters.xtol = 1e-6;
  lm.parameters.ftol = 1e-8;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(5);
  // Eigen's own tests stop at a relative step of xtol; the position is wanted to
  // a thousandth of a pixel, no finer: stop once a step moves the centre less
  // than kSettledMm and turns the clump less than kSettledRad.
  constexpr double kSettledMm = 1e-3, kSettledRad = 1e-4;
  auto status = lm.minimizeInit(x);
  if (status != Eigen::LevenbergMarquardtSpace::ImproperInputParameters) {
    do {
      const Eigen::VectorXd before = x;
      status = lm.minimizeOneStep(x);
      const Eigen::VectorXd step = x - before;
      if (step.head<2>().cwiseAbs().maxCoeff() < kSettledMm && step.tail<3>().cwiseAbs().maxCoeff() < kSettledRad) break;
    } while (status == Eigen::LevenbergMarquardtSpace::Running);
  }
  Eigen::VectorXd r(static_cast<Eigen::Index>(edges.size()));
  residuals(x, r);
  MarkerPose pose;
  pose.orientation = residuals.orientation(x);
  pose.centre = residuals.centre(x, pose.orientation);
  const Vec3 in_camera = camera_.toCamera(pose.centre);
  if (!(in_camera.z() > 0)) {
    pose.rms_px = std::numeric_limits<double>::infinity();
    return pose;
  }
  const geometry::Vec2 pixel = camera_.project(pose.centre);
  pose.pixel = {pixel.x(), pixel.y()};
  pose.rms_px = std::sqrt(r.squaredNorm() / static_cast<double>(r.size()));
  pose.edge_points = static_cast<int>(edges.size());
  return pose;
}

std::optional<MarkerPose> ShapeFitter::fit(const std::vector<cv::Point2f>& all_edges, cv::Point2d centroid,
                                           const MarkerPose* seed, cv::Point2d seed_centroid) const {
  if (static_cast<int>(all_edges.size()) < settings_.min_edge_points) return std::nullopt;
  // At most max_edge_points, evenly through the list (the outline in raster order):
  // the fit's cost is in proportion, its precision gains little beyond.
  thread_local std::vector<cv::Point2f> thinned;
  const std::vector<cv::Point2f>* chosen = &all_edges;
  if (static_cast<int>(all_edges.size()) > settings_.max_edge_points) {
    thinned.clear();
    const double stride = static_cast<double>(all_edges.size()) / settings_.max_edge_points;
    for (int i = 0; i < settings_.max_edge_points; ++i) thinned.push_back(all_edges[static_cast<std::size_t>(i * stride)]);
    chosen = &thinned;
  }
  const std::vector<cv::Point2f>& edges = *chosen;
  std::optional<MarkerPose> best;
  auto keep = [&](const MarkerPose& pose) {
    if (std::isfinite(pose.rms_px) && (!best || pose.rms_px < best->rms_px)) best = pose;
  };
  if (seed) {
    // The pose moves with the blob: the previous frame's fitted pixel shifted by
    // the centroid's motion, in the previous orientation.
    if (const auto start = poseThrough(seed->orientation, seed->pixel + (centroid - seed_centroid))) {
      keep(refine(edges, *start));
      // Poor: above the absolute limit and clearly worse than the track's last fit
      // (a marker partly hidden for a while fits worse every frame: no search for that).
      if (best && (best->rms_px <= settings_.reseed_rms_px || best->rms_px <= settings_.reseed_ratio * seed->rms_px))
        return best;
    }
  }
  // The search: every start orientation through the centroid, scored as it stands;
  // the best few refined.
  OutlineResiduals score;
  score.fitter = this;
  score.camera = &camera_;
  score.edges = &edges;
  score.along_u = along_u_;
  score.along_v = along_v_;
  score.robust_px = settings_.robust_px;
  std::vector<std::pair<double, MarkerPose>> scored;
  Eigen::VectorXd r(static_cast<Eigen::Index>(edges.size()));
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(5);
  for (const Eigen::Quaterniond& q : starts_) {
    const auto start = poseThrough(q, centroid);
    if (!start) continue;
    score.start_orientation = q;
    score.start_u = along_u_.dot(start->centre - model_.wall_point);
    score.start_v = along_v_.dot(start->centre - model_.wall_point);
    score(zero, r);
    scored.emplace_back(r.squaredNorm(), *start);
  }
  const std::size_t refined = std::min(scored.size(), static_cast<std::size_t>(settings_.refined_starts));
  std::partial_sort(scored.begin(), scored.begin() + static_cast<std::ptrdiff_t>(refined), scored.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  for (std::size_t i = 0; i < refined; ++i) {
    MarkerPose pose = refine(edges, scored[i].second);
    keep(pose);
  }
  if (best) best->searched = true;
  return best;
}

std::optional<ShapeChoice> fitBestShape(const std::vector<ShapeFitter>& fitters, const std::vector<cv::Point2f>& edges,
                                        cv::Point2d centroid) {
  std::optional<ShapeChoice> best;
  for (std::size_t k = 0; k < fitters.size(); ++k) {
    const std::optional<MarkerPose> pose = fitters[k].fit(edges, centroid);
    if (pose && (!best || pose->rms_px < best->pose.rms_px)) best = ShapeChoice{k, *pose};
  }
  return best;
}

void smoothFittedDepths(std::vector<Track>& tracks, const geometry::Camera& camera, const MarkerModel& model,
                        int half_window) {
  const Vec3 n = model.wall_normal.normalized();
  for (Track& track : tracks) {
    std::vector<std::size_t> fitted;
    std::vector<double> depth;
    for (std::size_t i = 0; i < track.points.size(); ++i)
      if (track.points[i].centre.allFinite()) {
        fitted.push_back(i);
        depth.push_back(n.dot(track.points[i].centre - model.wall_point));
      }
    std::vector<double> window;
    for (std::size_t k = 0; k < fitted.size(); ++k) {
      const std::size_t lo = k >= static_cast<std::size_t>(half_window) ? k - static_cast<std::size_t>(half_window) : 0;
      const std::size_t hi = std::min(fitted.size(), k + static_cast<std::size_t>(half_window) + 1);
      window.assign(depth.begin() + static_cast<std::ptrdiff_t>(lo), depth.begin() + static_cast<std::ptrdiff_t>(hi));
      const auto middle = window.begin() + static_cast<std::ptrdiff_t>(window.size() / 2);
      std::nth_element(window.begin(), middle, window.end());
      TrackPoint& p = track.points[fitted[k]];
      // The ray through the pixel, to the wall-parallel plane at the median depth.
      const Vec3 eye = camera.position();
      Vec3 ray;
      try {
        ray = camera.pixelRay(geometry::Vec2(p.pixel.x, p.pixel.y));
      } catch (const std::domain_error&) {
        continue;
      }
      const double along = ray.dot(n);
      if (std::abs(along) < 1e-12) continue;
      const double s = ((model.wall_point - eye).dot(n) + *middle) / along;
      if (s > 0) p.centre = eye + s * ray;
    }
  }
}

}  // namespace rocklab::track
