#pragma once
// The preview view of `rocklab shape` and `rocklab agglomerate`: two objects of size L
// side by side (centred at x = -0.6 L and +0.6 L), seen from the front and a little
// above, 960 x 480. Internal.
#include "rocklab/render/renderer.h"

namespace rocklab::experiments::detail {

/// Horizontal offset of each of the two objects from the middle (m).
inline double sideBySideShift(double size) {
  return 0.6 * size;
}

inline render::Renderer sideBySideRenderer(double size) {
  geometry::Camera cam = geometry::Camera::withFieldOfView(960, 480, 40.0);
  cam.lookAt(geometry::Vec3(0.0, -3.6 * size, 1.5 * size), geometry::Vec3::Zero(),
             geometry::Vec3::UnitZ());
  render::RenderOptions ro;
  ro.nearClip = 0.05 * size;
  ro.farClip = 20 * size;
  return render::Renderer(cam, ro);
}

}  // namespace rocklab::experiments::detail
