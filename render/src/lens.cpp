#include "lens.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace rocklab::render::detail {

using geometry::Vec2;

LensWarp makeLensWarp(const geometry::Camera& camera, int maxCanvas) {
  LensWarp warp;
  warp.canvas = {camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy};
  if (!camera.hasDistortion()) return warp;
  warp.active = true;

  // Undistorted pixel (on a canvas with the camera's own principal point) of a camera pixel.
  auto undistortedPixel = [&](double u, double v) {
    const Vec2 n = camera.undistort(Vec2((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy));
    return Vec2(camera.fx * n.x() + camera.cx, camera.fy * n.y() + camera.cy);
  };
  // Undistortion is radial and monotonic, so the image border bounds the region.
  double uLo = INFINITY, uHi = -INFINITY, vLo = INFINITY, vHi = -INFINITY;
  auto extend = [&](double u, double v) {
    const Vec2 p = undistortedPixel(u, v);
    uLo = std::min(uLo, p.x()), uHi = std::max(uHi, p.x());
    vLo = std::min(vLo, p.y()), vHi = std::max(vHi, p.y());
  };
  for (int i = 0; i <= camera.width; ++i) {
    extend(i - 0.5, -0.5);
    extend(i - 0.5, camera.height - 0.5);
  }
  for (int j = 0; j <= camera.height; ++j) {
    extend(-0.5, j - 0.5);
    extend(camera.width - 0.5, j - 0.5);
  }
  // Two pixels of margin for the bilinear footprint; whole-pixel shifts keep the
  // canvas grid aligned with the camera grid at the principal point.
  const int left = static_cast<int>(std::floor(uLo)) - 2, right = static_cast<int>(std::ceil(uHi)) + 2;
  const int top = static_cast<int>(std::floor(vLo)) - 2, bottom = static_cast<int>(std::ceil(vHi)) + 2;
  Canvas& c = warp.canvas;
  c.width = right - left + 1;
  c.height = bottom - top + 1;
  c.cx = camera.cx - left;
  c.cy = camera.cy - top;
  if (c.width > maxCanvas || c.height > maxCanvas)
    throw std::invalid_argument("camera.k1 and camera.k2: the undistorted view needs a " + std::to_string(c.width) +
                                " x " + std::to_string(c.height) + " pixel canvas (at most " +
                                std::to_string(maxCanvas) + "); the distortion is too strong");

  warp.mapX.create(camera.height, camera.width, CV_32F);
  warp.mapY.create(camera.height, camera.width, CV_32F);
  for (int v = 0; v < camera.height; ++v) {
    auto* mx = warp.mapX.ptr<float>(v);
    auto* my = warp.mapY.ptr<float>(v);
    for (int u = 0; u < camera.width; ++u) {
      const Vec2 p = undistortedPixel(u, v);
      mx[u] = static_cast<float>(p.x() - left);
      my[u] = static_cast<float>(p.y() - top);
    }
  }
  return warp;
}

void applyLensWarp(const LensWarp& warp, const cv::Mat& canvasImage, cv::Mat& out) {
  if (!warp.active) {
    out = canvasImage;
    return;
  }
  cv::remap(canvasImage, out, warp.mapX, warp.mapY, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
}

}  // namespace rocklab::render::detail
