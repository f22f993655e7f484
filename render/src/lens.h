#pragma once
// Lens distortion as a post-process: the scene is drawn undistorted on a canvas
// that covers the distorted field of view, then each output pixel samples the
// canvas where the undistorted ray of that pixel lands (cv::remap).
#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"

namespace rocklab::render::detail {

/// The undistorted pinhole image the GL pass draws: same focal lengths as the
/// camera, principal point shifted by whole pixels.
struct Canvas {
  int width = 0, height = 0;     // pixels
  double fx = 0, fy = 0;         // pixels
  double cx = 0, cy = 0;         // pixels, OpenCV convention
};

struct LensWarp {
  Canvas canvas;
  bool active = false;           // false: canvas == camera image, no warp
  cv::Mat mapX, mapY;            // CV_32F, camera.height × camera.width: canvas coordinates
};

/// Canvas and maps for a (validated) camera. Throws std::invalid_argument when
/// the distortion would need a canvas larger than maxCanvas pixels on a side.
LensWarp makeLensWarp(const geometry::Camera& camera, int maxCanvas = 8192);

/// Output image (camera size) from the canvas image, bilinear.
void applyLensWarp(const LensWarp& warp, const cv::Mat& canvasImage, cv::Mat& out);

}  // namespace rocklab::render::detail
