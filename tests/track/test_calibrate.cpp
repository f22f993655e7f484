// Lab-style calibration on rendered checkerboards: the renderer draws a 9×6
// inner-corner board of 20 mm squares through a known camera from six poses; the
// tracker, seeing only the images, recovers the intrinsics and the board's plane.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "rocklab/render/calibration_target.h"
#include "rocklab/render/renderer.h"
#include "rocklab/track/calibrate.h"
#include "rocklab/track/plane.h"
#include "track_scenes.h"

using namespace rocklab;
using namespace rocklab::track;
using namespace rocklab::track::test;

namespace {

constexpr int kCols = 9, kRows = 6;  // inner corners
constexpr double kSquare = 0.020;    // m

// The true camera: 640×480, fx = fy = 800, off-centre principal point, k1 = −0.05.
Camera trueCamera() {
  Camera c;
  c.fx = 800.0;
  c.fy = 800.0;
  c.cx = 322.3;
  c.cy = 236.8;
  c.k1 = -0.05;
  return c;
}

// Six poses, as a lab would take them: tilt θ from the board normal, azimuth φ,
// roll from the `up` direction ψ (degrees), at distance d (m), looking at a point
// (ox, oy) m off the board centre so the board also fills the image corners,
// where the distortion shows.
std::vector<Camera> poses() {
  const Vec3 centre(0.5 * (kCols - 1) * kSquare, 0.5 * (kRows - 1) * kSquare, 0.0);
  const double deg = std::numbers::pi / 180.0;
  const double table[6][6] = {{20, 0, 90, 0.50, 0.0, 0.0},       {30, 90, 60, 0.50, 0.03, 0.02},
                              {35, 180, 115, 0.50, -0.03, 0.02}, {30, 270, 80, 0.50, 0.03, -0.02},
                              {25, 45, 100, 0.50, -0.03, -0.02}, {30, 225, 70, 0.52, 0.0, 0.0}};
  std::vector<Camera> out;
  for (const auto& row : table) {
    const double theta = row[0] * deg, phi = row[1] * deg, psi = row[2] * deg;
    const Vec3 target = centre + Vec3(row[4], row[5], 0.0);
    Camera c = trueCamera();
    const Vec3 eye = target + row[3] * Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    c.lookAt(eye, target, Vec3(std::cos(psi), std::sin(psi), 0.0));
    out.push_back(c);
  }
  return out;
}

std::vector<cv::Mat> renderBoards(const std::vector<Camera>& cameras) {
  const render::FrameDescription board = checkerboard(kCols, kRows, kSquare);
  render::Renderer renderer(cameras.front());
  std::vector<cv::Mat> images;
  for (const Camera& c : cameras) {
    renderer.setCamera(c);
    images.push_back(renderer.render(board));
    if (std::getenv("ROCKLAB_TRACK_SAVE"))
      cv::imwrite("/tmp/track_board_" + std::to_string(images.size() - 1) + ".png", images.back());
  }
  return images;
}

}  // namespace

TEST_CASE("calibration from rendered checkerboards recovers the focal lengths", "[track][calibrate]") {
  const std::vector<Camera> cameras = poses();
  const std::vector<cv::Mat> images = renderBoards(cameras);
  const CalibrationResult c = calibrateFromCheckerboards(images, {kCols, kRows}, kSquare);
  const Camera truth = trueCamera();
  std::printf("calibration of 6 rendered boards: fx %.3f (true 800, %+.3f %%), fy %.3f (%+.3f %%), cx %.2f (322.3), "
              "cy %.2f (236.8), k1 %+.4f (-0.05), k2 %+.4f (0), rms %.3f px\n",
              c.fx, 100 * (c.fx / truth.fx - 1), c.fy, 100 * (c.fy / truth.fy - 1), c.cx, c.cy, c.k1, c.k2, c.rms_px);
  CHECK(c.fx == Approx(truth.fx).epsilon(0.005));
  CHECK(c.fy == Approx(truth.fy).epsilon(0.005));
  CHECK(std::abs(c.cx - truth.cx) < 3.0);
  CHECK(std::abs(c.cy - truth.cy) < 3.0);
  // Distortion: measured k1 -0.0528 (true -0.05), k2 -0.0298 (true 0): k1 and k2
  // trade off against each other over boards that reach r^2 = 0.25 (the image
  // corner), so each is held to twice its measured error, and their joint effect,
  // the radial shift at the corner r (k1 r^2 + k2 r^4 - k1_true r^2) fx, to 2 px
  // (measured 1.0 px; a fit without k1 would be 5 px off there).
  CHECK(std::abs(c.k1 - truth.k1) < 0.006);
  CHECK(std::abs(c.k2 - truth.k2) < 0.06);
  const double r2 = std::pow(320.0 / 800.0, 2) + std::pow(240.0 / 800.0, 2);
  CHECK(std::abs(((c.k1 - truth.k1) * r2 + (c.k2 - truth.k2) * r2 * r2) * std::sqrt(r2) * truth.fx) < 2.0);
  CHECK(c.rms_px < 0.2);
  CHECK(c.rvecs.size() == 6);
  CHECK(c.image_size == cv::Size(640, 480));

  // The board's plane in image 1, against the true pose (board frame = world frame).
  const PlanePose pose = checkerboardPlanePose(images[1], {kCols, kRows}, kSquare, c);
  const Vec3 trueNormal = cameras[1].rotation.col(2), truePoint = cameras[1].translation;
  const double angle = std::acos(std::min(1.0, std::abs(pose.normal.dot(trueNormal)))) * 180.0 / std::numbers::pi;
  const double distance = std::abs(pose.normal.dot(pose.point)), trueDistance = std::abs(trueNormal.dot(truePoint));
  std::printf("board plane in image 1: normal %.3f deg off, distance %.2f mm (true %.2f mm), rms %.3f px\n", angle,
              1e3 * distance, 1e3 * trueDistance, pose.rms_px);
  CHECK(angle < 0.5);
  CHECK(distance == Approx(trueDistance).epsilon(0.005));

  // With the board as the world: two true corners seen in image 1, taken back to
  // the board plane, lie the board diagonal apart.
  const Camera measured = calibratedCamera(c, pose);
  const Vec2 first = cameras[1].project(Vec3::Zero());
  const Vec2 last = cameras[1].project(Vec3((kCols - 1) * kSquare, (kRows - 1) * kSquare, 0));
  const auto a = pixelToPlane(measured, {first.x(), first.y()}, Vec3::Zero(), Vec3::UnitZ());
  const auto b = pixelToPlane(measured, {last.x(), last.y()}, Vec3::Zero(), Vec3::UnitZ());
  REQUIRE(a);
  REQUIRE(b);
  const double diagonal = std::hypot((kCols - 1) * kSquare, (kRows - 1) * kSquare);
  std::printf("board diagonal measured through the calibrated camera: %.3f mm (true %.3f mm)\n", 1e3 * (*a - *b).norm(),
              1e3 * diagonal);
  CHECK(std::abs((*a - *b).norm() - diagonal) < 5e-4);
  CHECK(std::abs(a->z()) < 1e-12);
}

TEST_CASE("calibration names the image whose corners are not found", "[track][calibrate]") {
  std::vector<Camera> cameras = poses();
  cameras.resize(3);
  std::vector<cv::Mat> images = renderBoards(cameras);
  images[2] = cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 90, 90));
  CHECK_THROWS_WITH(calibrateFromCheckerboards(images, {kCols, kRows}, kSquare),
                    Catch::Contains("found in image 2 (of 3)") && Catch::Contains("9x6"));
  CHECK_THROWS_WITH(calibrateFromCheckerboards({images[0], images[1]}, {kCols, kRows}, kSquare),
                    Catch::Contains("at least 3 images"));
  CHECK_THROWS_WITH(checkerboardPlanePose(images[2], {kCols, kRows}, kSquare, CalibrationResult{}),
                    Catch::Contains("no 9x6"));
}

TEST_CASE("an upright board is read right and up whichever corner the detector starts from", "[track][calibrate]") {
  // The lab's board on a wall (the plane y = 0, seen from -y): columns along +x,
  // rows up (+z). Photographed upright and with the camera rolled by 180 deg,
  // findChessboardCorners starts from different corners; the board frame read
  // with BoardAxes::RightAndUp follows the image (right, up) either way.
  const std::vector<Camera> cameras = poses();
  const CalibrationResult c = calibrateFromCheckerboards(renderBoards(cameras), {kCols, kRows}, kSquare);
  render::BoardPlacement wall;
  wall.rotation.col(0) = Vec3::UnitX();
  wall.rotation.col(1) = Vec3::UnitZ();
  wall.rotation.col(2) = -Vec3::UnitY();  // x × y: towards the camera
  wall.origin = Vec3(-0.08, 0.0, -0.05);
  const render::FrameDescription board = render::checkerboardFrame({kCols, kRows, kSquare}, wall);
  for (const Vec3& up : std::vector<Vec3>{Vec3::UnitZ(), Vec3(0.2, 0.0, 1.0), Vec3(0.0, 0.0, -1.0)}) {
    Camera camera = trueCamera();
    camera.lookAt(Vec3(0.0, -0.45, 0.01), Vec3(0.0, 0.0, 0.0), up);
    render::Renderer renderer(camera);
    const cv::Mat image = renderer.render(board);
    const PlanePose pose = checkerboardPlanePose(image, {kCols, kRows}, kSquare, c, BoardAxes::RightAndUp);
    // Upright in the image: the board's x is the camera's right, its y the camera's up.
    const Vec3 right = pose.rotation.col(0), rows = pose.rotation.col(1);
    INFO("camera up " << up.transpose() << ": board x in camera " << right.transpose() << ", y " << rows.transpose());
    CHECK(right.x() > 0.9);
    CHECK(rows.y() < -0.9);  // camera y points down in the image
    CHECK(pose.normal.z() < -0.99);  // towards the camera
    if (up.z() > 0) {  // upright camera: the frame found is the lab's placement
      const geometry::Mat3 expected = camera.rotation * wall.rotation;
      CHECK((pose.rotation - expected).norm() < 0.02);
      CHECK((pose.translation - camera.toCamera(wall.origin)).norm() < 1e-3);
    }
  }
}
