#include "camera/camera_calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "rocklab/track/calibrate.h"

namespace rocklab::experiments {

using geometry::Mat3;
using geometry::Vec3;

namespace {

// The photographs after the first (flat on the wall), as a lab takes them so that
// focal length, distortion and distance separate: the board held in front of the
// wall at `depth` (fraction of the camera's distance to the wall, so it fills
// more of the image), tilted about its x and y axes (deg), its centre shifted
// along them (fractions of the view at that depth) towards the image edges.
struct Tilt {
  double about_x_deg, about_y_deg, shift_x, shift_y, depth;
};
constexpr Tilt kTilts[] = {
    {0, 40, -0.2, 0, 0.55}, {0, -40, 0.2, 0, 0.55},  {35, 0, 0, 0, 0.55},      {-35, 0, 0, 0, 0.55},
    {25, 30, 0.2, 0, 0.55}, {-25, -30, -0.2, 0, 0.55}, {-25, 30, 0, 0, 0.55},   {25, -30, 0, 0, 0.55},
    {30, 25, -0.2, 0, 0.5}, {-30, -25, 0.2, 0, 0.5}};

Mat3 rotationAbout(const Vec3& axis, double degrees) {
  return Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, axis.normalized()).toRotationMatrix();
}

nlohmann::json versus(double recovered, double truth) {
  return {{"recovered", recovered}, {"true", truth}, {"error", recovered - truth}};
}

}  // namespace

WallCalibration calibrateOnWall(const geometry::Camera& truth, const render::RenderOptions& options,
                                const Vec3& wall_point, const Vec3& wall_normal, int photos) {
  const auto t0 = std::chrono::steady_clock::now();
  if (photos < 3 || photos > 1 + static_cast<int>(std::size(kTilts)))
    throw std::invalid_argument("calibration photos must be 3 to " + std::to_string(1 + std::size(kTilts)) +
                                " (got " + std::to_string(photos) + ")");
  const Vec3 n = wall_normal.normalized();
  // Where the optical axis meets the wall, and how much of the wall the view holds there.
  const Vec3 eye = truth.position(), axis = truth.rotation.row(2).transpose();
  const double along = (wall_point - eye).dot(n) / axis.dot(n);
  if (!(along > 0.0) || !std::isfinite(along))
    throw std::runtime_error("calibration: the camera does not look at the camera-side wall");
  const Vec3 centre = eye + along * axis;
  const double view_w = along * truth.width / truth.fx, view_h = along * truth.height / truth.fy;

  // A board with its border filling half the shorter view at the wall, squares in whole mm;
  // its x axis along the image's right on the wall, y up, z = x × y = the wall normal.
  WallCalibration out;
  render::Checkerboard& board = out.board;
  if (view_h > view_w) std::swap(board.inner_cols, board.inner_rows);  // the board's long side along the view's
  board.square = 1e-3 * std::floor(1e3 * 0.5 * std::min(view_w / (board.inner_cols + 3), view_h / (board.inner_rows + 3)));
  Mat3 upright;
  upright.col(0) = (truth.rotation.row(0).transpose() - n * n.dot(truth.rotation.row(0).transpose())).normalized();
  upright.col(2) = n;
  upright.col(1) = n.cross(upright.col(0));
  const auto placementsOf = [&](const render::Checkerboard& b) {
    const Vec3 half_grid(0.5 * (b.inner_cols - 1) * b.square, 0.5 * (b.inner_rows - 1) * b.square, 0.0);
    std::vector<render::BoardPlacement> list;
    list.push_back({upright, centre - upright * half_grid});  // flat on the wall: the reference
    for (int k = 1; k < photos; ++k) {
      const Tilt& t = kTilts[k - 1];
      const Mat3 r = upright * rotationAbout(Vec3::UnitX(), t.about_x_deg) * rotationAbout(Vec3::UnitY(), t.about_y_deg);
      const Vec3 c = eye + t.depth * (centre - eye) + upright * (t.depth * Vec3(t.shift_x * view_w, t.shift_y * view_h, 0.0));
      list.push_back({r, c - r * half_grid});
    }
    return list;
  };
  // Every photo must hold the board's squares whole (the detector needs the outer ones;
  // of the white border around them, a part may be cut): the held and tilted boards come
  // nearer the camera, and in a view less wide than the board a tilted one left it (16:9
  // images lost their ninth photo, so the camera went uncalibrated). Smaller squares
  // until every photo holds them.
  const auto inView = [&](const render::Checkerboard& b, const render::BoardPlacement& p) {
    const double lo = -b.square, hi_x = b.inner_cols * b.square, hi_y = b.inner_rows * b.square;
    const double mx = 0.5, my = 0.5;  // px: the image's edge pixels
    for (const Vec3& corner : {Vec3(lo, lo, 0), Vec3(hi_x, lo, 0), Vec3(lo, hi_y, 0), Vec3(hi_x, hi_y, 0)}) {
      const Vec3 world = p.toWorld(corner);
      if (!((world - eye).dot(axis) > 0.0)) return false;  // behind the camera
      const geometry::Vec2 px = truth.project(world);
      if (!(px.x() >= mx && px.x() <= truth.width - mx && px.y() >= my && px.y() <= truth.height - my)) return false;
    }
    return true;
  };
  std::vector<render::BoardPlacement> placements = placementsOf(board);
  while (board.square >= 1e-3 &&
         !std::all_of(placements.begin(), placements.end(), [&](const auto& p) { return inView(board, p); })) {
    board.square = 1e-3 * std::floor(1e3 * 0.9 * board.square);
    placements = placementsOf(board);
  }
  if (!(board.square >= 1e-3)) throw std::runtime_error("calibration: the view of the wall is too small for a board");
  render::Renderer renderer(truth, options);
  std::vector<cv::Mat> images;
  for (const render::BoardPlacement& p : placements) images.push_back(renderer.render(render::checkerboardFrame(board, p)));

  const cv::Size inner(board.inner_cols, board.inner_rows);
  const track::CalibrationResult c = track::calibrateFromCheckerboards(images, inner, board.square);
  const track::PlanePose pose =
      track::checkerboardPlanePose(images.front(), inner, board.square, c, track::BoardAxes::RightAndUp);
  // Board → camera (solvePnP) composed with world → board (the known placement).
  const render::BoardPlacement& flat = placements.front();
  geometry::Camera& cam = out.camera;
  cam = track::calibratedCamera(c, pose);
  cam.rotation = pose.rotation * flat.rotation.transpose();
  cam.translation = pose.translation - cam.rotation * flat.origin;
  cam.frameRate = truth.frameRate;
  cam.exposureTime = truth.exposureTime;

  const Vec3 view_true = truth.rotation.row(2).transpose(), view_found = cam.rotation.row(2).transpose();
  const double view_angle = std::acos(std::clamp(view_true.dot(view_found), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  out.report = {{"method", "checkerboard photographs, cv::calibrateCamera (k1, k2) + cv::solvePnP of the board "
                           "flat on the camera-side wall"},
                {"photos", photos},
                {"inner_corners", {board.inner_cols, board.inner_rows}},
                {"square_m", board.square},
                {"rms_reprojection_px", c.rms_px},
                {"fx_px", versus(c.fx, truth.fx)},
                {"fy_px", versus(c.fy, truth.fy)},
                {"cx_px", versus(c.cx, truth.cx)},
                {"cy_px", versus(c.cy, truth.cy)},
                {"k1", versus(c.k1, truth.k1)},
                {"k2", versus(c.k2, truth.k2)},
                {"camera_position_error_m", (cam.position() - truth.position()).norm()},
                {"view_direction_error_deg", view_angle},
                {"wall_time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  return out;
}

}  // namespace rocklab::experiments
