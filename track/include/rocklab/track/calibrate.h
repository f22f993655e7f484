#pragma once
// Lab-style camera calibration from photographs of a planar checkerboard, and the
// pose of a board (the plane it lies on) in one photograph.
//
// Board frame: corner (row i, column j) of the inner-corner grid, in the order
// cv::findChessboardCorners returns them, is at (j · square, i · square, 0) m.
// findChessboardCorners may start the grid from either end, so the board's in-plane
// axes (and the sign of its normal) may differ from photo to photo; the plane does not.
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/vec.h"

namespace rocklab::track {

struct CalibrationResult {
  double fx = 0, fy = 0, cx = 0, cy = 0;  // px, OpenCV / geometry::Camera convention
  double k1 = 0, k2 = 0;                  // radial distortion; p1 = p2 = k3 = 0 (fixed)
  double rms_px = 0;                      // RMS reprojection error over all corners
  std::vector<cv::Mat> rvecs, tvecs;      // board → camera pose of each image (Rodrigues, m)
  cv::Size image_size;                    // px
};

/// findChessboardCorners + cornerSubPix on each image, then cv::calibrateCamera with
/// tangential distortion and k3 fixed at zero. Images: 8-bit grey or BGR, all the
/// same size, at least 3. Throws std::invalid_argument for bad arguments and
/// std::runtime_error naming the image index when its corners are not found.
CalibrationResult calibrateFromCheckerboards(const std::vector<cv::Mat>& images, cv::Size inner_corners,
                                             double square_m);

/// A board's plane in the camera frame.
struct PlanePose {
  geometry::Vec3 point = geometry::Vec3::Zero();   // m, camera frame: the board origin (first corner)
  geometry::Vec3 normal = geometry::Vec3::UnitZ(); // camera frame, unit: the board's +z
  geometry::Mat3 rotation = geometry::Mat3::Identity();  // board → camera
  geometry::Vec3 translation = geometry::Vec3::Zero();   // m, board → camera (= point)
  double rms_px = 0;                               // reprojection error of this image
};

/// Which way the board frame is read from the image.
enum class BoardAxes {
  AsFound,     // findChessboardCorners' order (may start from any corner)
  RightAndUp,  // the lab's convention for a board placed upright: its x axis (columns)
               // points right in the image, its y axis (rows) up, so z = x × y points
               // towards the camera. Unambiguous while the board is turned less than
               // 45° in the image.
};

/// cv::solvePnP of the board in one image with calibrated intrinsics. Throws
/// std::runtime_error when the corners are not found.
PlanePose checkerboardPlanePose(const cv::Mat& image, cv::Size inner_corners, double square_m,
                                const CalibrationResult& calibration, BoardAxes axes = BoardAxes::AsFound);

/// The calibrated camera with the board as the world frame (x, y on the board,
/// z = 0 its plane): pixelToPlane(camera, px, 0, UnitZ) then reads board coordinates.
geometry::Camera calibratedCamera(const CalibrationResult& calibration, const PlanePose& board);

}  // namespace rocklab::track
