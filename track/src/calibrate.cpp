#include "rocklab/track/calibrate.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace rocklab::track {

namespace {

std::string sizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

cv::Mat toGrey(const cv::Mat& image) {
  if (image.type() == CV_8UC1) return image;
  if (image.type() == CV_8UC3) {
    cv::Mat grey;
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    return grey;
  }
  throw std::invalid_argument("checkerboard image must be 8-bit grey or BGR");
}

// Inner corners of the board to sub-pixel accuracy; empty when not found.
std::vector<cv::Point2f> findCorners(const cv::Mat& image, cv::Size inner) {
  const cv::Mat grey = toGrey(image);
  std::vector<cv::Point2f> corners;
  const int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE;
  if (!cv::findChessboardCorners(grey, inner, corners, flags)) {
    // Sensor noise breaks the detector's quads long before it moves the corners:
    // find the grid on a smoothed copy, refine on the photograph itself.
    cv::Mat smooth;
    cv::GaussianBlur(grey, smooth, cv::Size(0, 0), 1.5);
    if (!cv::findChessboardCorners(smooth, inner, corners, flags)) return {};
  }
  // Search window: a little under half the smallest corner spacing (so it never
  // reaches the next corner), at most 11 px.
  double spacing = 1e9;
  for (int i = 0; i < inner.height; ++i)
    for (int j = 0; j + 1 < inner.width; ++j)
      spacing = std::min<double>(spacing, cv::norm(corners[i * inner.width + j + 1] - corners[i * inner.width + j]));
  for (int i = 0; i + 1 < inner.height; ++i)
    for (int j = 0; j < inner.width; ++j)
      spacing = std::min<double>(spacing, cv::norm(corners[(i + 1) * inner.width + j] - corners[i * inner.width + j]));
  const int half = std::clamp(static_cast<int>(0.4 * spacing), 2, 11);
  cv::cornerSubPix(grey, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  return corners;
}

// Corner (row i, column j) at (j · square, i · square, 0), row by row.
std::vector<cv::Point3f> boardPoints(cv::Size inner, double square) {
  std::vector<cv::Point3f> points;
  for (int i = 0; i < inner.height; ++i)
    for (int j = 0; j < inner.width; ++j)
      points.emplace_back(static_cast<float>(j * square), static_cast<float>(i * square), 0.0f);
  return points;
}

void checkBoard(cv::Size inner, double square) {
  if (inner.width < 2 || inner.height < 2)
    throw std::invalid_argument("checkerboard inner_corners must be at least 2x2 (got " + sizeText(inner) + ")");
  if (!(square > 0.0) || !std::isfinite(square))
    throw std::invalid_argument("checkerboard square_m must be a finite length > 0 m");
}

// Reorders a row-major corner grid so that columns run right (+u) and rows up (−v)
// in the image: a mirror within rows and/or of the row order.
void orientRightAndUp(std::vector<cv::Point2f>& corners, cv::Size inner) {
  const auto at = [&](int i, int j) -> cv::Point2f& { return corners[static_cast<std::size_t>(i * inner.width + j)]; };
  const cv::Point2f along_row = at(0, inner.width - 1) - at(0, 0);
  const cv::Point2f along_column = at(inner.height - 1, 0) - at(0, 0);
  if (along_row.x < 0)
    for (int i = 0; i < inner.height; ++i) std::reverse(&at(i, 0), &at(i, 0) + inner.width);
  if (along_column.y > 0)
    for (int i = 0; i < inner.height / 2; ++i)
      std::swap_ranges(&at(i, 0), &at(i, 0) + inner.width, &at(inner.height - 1 - i, 0));
}

cv::Mat cameraMatrix(const CalibrationResult& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

}  // namespace

CalibrationResult calibrateFromCheckerboards(const std::vector<cv::Mat>& images, cv::Size inner_corners,
                                             double square_m) {
  checkBoard(inner_corners, square_m);
  if (images.size() < 3)
    throw std::invalid_argument("calibrateFromCheckerboards needs at least 3 images (got " +
                                std::to_string(images.size()) + ")");
  const cv::Size size = images.front().size();
  std::vector<std::vector<cv::Point2f>> imagePoints;
  for (std::size_t k = 0; k < images.size(); ++k) {
    if (images[k].size() != size)
      throw std::invalid_argument("calibrateFromCheckerboards: image " + std::to_string(k) + " is " +
                                  sizeText(images[k].size()) + ", image 0 is " + sizeText(size));
    std::vector<cv::Point2f> corners = findCorners(images[k], inner_corners);
    if (corners.empty())
      throw std::runtime_error("calibrateFromCheckerboards: no " + sizeText(inner_corners) +
                               " inner-corner checkerboard found in image " + std::to_string(k) + " (of " +
                               std::to_string(images.size()) + ")");
    imagePoints.push_back(std::move(corners));
  }
  const std::vector<std::vector<cv::Point3f>> objectPoints(images.size(), boardPoints(inner_corners, square_m));

  // Radial k1, k2 only: the camera model has no tangential terms and no k3.
  cv::Mat k, dist;
  CalibrationResult out;
  out.rms_px = cv::calibrateCamera(objectPoints, imagePoints, size, k, dist, out.rvecs, out.tvecs,
                                   cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3,
                                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  out.fx = k.at<double>(0, 0);
  out.fy = k.at<double>(1, 1);
  out.cx = k.at<double>(0, 2);
  out.cy = k.at<double>(1, 2);
  out.k1 = dist.at<double>(0);
  out.k2 = dist.at<double>(1);
  out.image_size = size;
  return out;
}

PlanePose checkerboardPlanePose(const cv::Mat& image, cv::Size inner_corners, double square_m,
                                const CalibrationResult& calibration, BoardAxes axes) {
  checkBoard(inner_corners, square_m);
  std::vector<cv::Point2f> corners = findCorners(image, inner_corners);
  if (corners.empty())
    throw std::runtime_error("checkerboardPlanePose: no " + sizeText(inner_corners) +
                             " inner-corner checkerboard found in the image");
  if (axes == BoardAxes::RightAndUp) orientRightAndUp(corners, inner_corners);
  const std::vector<cv::Point3f> board = boardPoints(inner_corners, square_m);
  const cv::Mat k = cameraMatrix(calibration);
  const cv::Mat dist = (cv::Mat_<double>(4, 1) << calibration.k1, calibration.k2, 0.0, 0.0);
  cv::Mat rvec, tvec, rotation;
  cv::solvePnP(board, corners, k, dist, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE);
  cv::Rodrigues(rvec, rotation);

  PlanePose pose;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) pose.rotation(i, j) = rotation.at<double>(i, j);
    pose.translation(i) = tvec.at<double>(i);
  }
  pose.point = pose.translation;          // the board origin in the camera frame
  pose.normal = pose.rotation.col(2);     // the board's +z in the camera frame
  // Reprojection error of this image.
  std::vector<cv::Point2f> projected;
  cv::projectPoints(board, rvec, tvec, k, dist, projected);
  double sum = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const cv::Point2f d = projected[i] - corners[i];
    sum += d.dot(d);
  }
  pose.rms_px = std::sqrt(sum / static_cast<double>(corners.size()));
  return pose;
}

geometry::Camera calibratedCamera(const CalibrationResult& calibration, const PlanePose& board) {
  geometry::Camera camera;
  camera.width = calibration.image_size.width;
  camera.height = calibration.image_size.height;
  camera.fx = calibration.fx;
  camera.fy = calibration.fy;
  camera.cx = calibration.cx;
  camera.cy = calibration.cy;
  camera.k1 = calibration.k1;
  camera.k2 = calibration.k2;
  camera.rotation = board.rotation;        // x_cam = R x_board + t: the board is the world
  camera.translation = board.translation;
  return camera;
}

}  // namespace rocklab::track
