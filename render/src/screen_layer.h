#pragma once
// Transparent walls in front of everything that moves (the Perspex side of a chute,
// which the camera films through) cost llvmpipe a blended pass over most of the
// canvas every frame: an eighth of a frame's CPU in the render benchmark. When every
// sphere lies beyond them (SpherePass::behindScreens) they add the same thing every
// frame, so they are drawn once into a float layer, depth-tested against the opaque
// walls as in the frame, and laid over each frame on the CPU.
//
// The layer is the walls' "over" composite on a clear canvas: colour C (premultiplied)
// and coverage A, so that drawing the walls far to near over any pixel d gives
// C + (1 − A) d exactly in real numbers (the blend of one wall is α L + (1 − α) d;
// two in a row, α₂ L₂ + (1 − α₂)(α₁ L₁ + (1 − α₁) d) = C + (1 − A) d). The 8-bit
// result can differ by one level from blending wall by wall in 8 bits.
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "framebuffer.h"
#include "gl_api.h"
#include "surface_pass.h"
#include "view.h"

namespace rocklab::render::detail {

class ScreenLayer {
 public:
  ScreenLayer(const GlApi& gl, int width, int height);

  /// Redraws the layer when `key` (everything its pixels depend on) changed: the
  /// depth of `opaque`, then the transparent draws of `surfaces` over a clear canvas.
  /// Leaves another framebuffer bound.
  void update(const std::vector<double>& key, const Framebuffer& opaque, const SurfacePass& surfaces,
              const ViewUniforms& view);
  /// rgba (CV_8UC4, canvas-sized) ← C + (1 − A) rgba, rounded; alpha untouched.
  void composite(cv::Mat& rgba) const;

  /// Fixed point of the weights: 1 − A and 255 C in steps of 1/256 (within half a
  /// level of the exact blend, whose rounding adds up to half a level more).
  /// Composited 16 channels at a time (SSE2), one thread: about a tenth of a
  /// millisecond at 640 × 480.
  static constexpr int kFractionBits = 8;

 private:
  const GlApi& gl_;
  Framebuffer layer_;      // RGBA32F + depth
  std::vector<double> key_;
  // Per channel (r, g, b, a), 16-bit fixed point: out = (keep in + add) >> kFractionBits,
  // add holding the rounding, keep × 255 + add < 2^16; alpha is kept (keep 1, add 0).
  std::vector<std::uint16_t> keep_, add_;
};

}  // namespace rocklab::render::detail
