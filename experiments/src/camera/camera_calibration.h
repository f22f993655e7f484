#pragma once
// The lab's camera calibration before a tracked run: a printed checkerboard held
// in front of the fixed camera in several poses, the first laid flat on the
// camera-side wall where the lab taped it (upright in the view, its first inner
// corner at a measured point). The tracker then works with the
// recovered camera only: intrinsics from cv::calibrateCamera over all photos,
// the pose from cv::solvePnP of the flat board, expressed in the chute frame
// through the known board placement. The renderer's true camera is used only to
// take the photographs and, afterwards, to report how far the recovery is off.
#include <nlohmann/json.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/render/calibration_target.h"
#include "rocklab/render/renderer.h"

namespace rocklab::experiments {

struct WallCalibration {
  geometry::Camera camera;     // recovered, chute (world) frame; frame rate and exposure copied
  render::Checkerboard board;  // the board used
  nlohmann::json report;       // recovered against true values
};

/// Photographs with `truth` a checkerboard sized to the view in `photos` poses
/// (3 to 11; the first flat on the wall plane through `wall_point` with unit normal
/// `wall_normal` towards the camera, centred on the optical axis, upright in the
/// image), calibrates and returns the recovered camera. Throws std::runtime_error
/// when the board is not found in a photograph (a camera that does not see the wall).
WallCalibration calibrateOnWall(const geometry::Camera& truth, const render::RenderOptions& options,
                                const geometry::Vec3& wall_point, const geometry::Vec3& wall_normal, int photos);

}  // namespace rocklab::experiments
