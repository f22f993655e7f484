#pragma once
// Annotations drawn onto rendered frames (after rendering, so tracking tests
// should use frames without them).
#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"

namespace rocklab::render {

struct OverlayStyle {
  cv::Scalar colour{255, 255, 255};  // BGR; drawn over a dark outline
  double fontScale = 0.5;
  int thickness = 1;                 // pixels
  int margin = 8;                    // pixels from the image edge
};

/// "t = 0.1234 s" in the top-left corner.
void drawTimestamp(cv::Mat& image, double time_s, int decimals = 4, const OverlayStyle& style = {});

/// A scale bar in the bottom-left corner, true at distance `depth_m` along the
/// optical axis (length in pixels = fx · length / depth; distortion ignored).
/// length_mm ≤ 0 picks a round 1-2-5 length near a fifth of the image width.
/// Returns the length drawn [mm].
double drawScaleBar(cv::Mat& image, const geometry::Camera& camera, double depth_m, double length_mm = 0.0,
                    const OverlayStyle& style = {});

}  // namespace rocklab::render
