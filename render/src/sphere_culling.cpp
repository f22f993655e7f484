#include "sphere_culling.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rocklab::render::detail {

namespace {

// Image of a sphere around its projected centre (u, v): every pixel it touches
// (soft edge included) lies within `outer`; every pixel within `inner` is fully
// covered. With d = |c|, α = asin(r/d) and θ the angle of c off the optical axis,
// the image is an ellipse with radial ends at f tan(θ ± α) and semi-axes ≥ f sin α;
// the projected centre sits δ = f ((tan(θ+α) + tan(θ−α))/2 − tan θ) outward of the
// ellipse centre. Half a pixel more (less) for the antialiased edge ramp.
struct Footprint {
  double u, v, inner, outer;
  bool valid;
};

Footprint footprint(const CameraSphere& s, const Canvas& canvas) {
  const double x = s.x, y = s.y, z = s.z, r = s.radius;
  const double d = std::sqrt(x * x + y * y + z * z);
  const double alpha = std::asin(r / d), theta = std::acos(std::clamp(z / d, -1.0, 1.0));
  const double fMin = std::min(canvas.fx, canvas.fy), fMax = std::max(canvas.fx, canvas.fy);
  if (theta + alpha > 1.45) return {0, 0, 0, 0, false};  // near 90° off axis: no useful bound
  const double tp = std::tan(theta + alpha), tm = std::tan(theta - alpha), t = std::tan(theta);
  const double delta = fMax * std::abs(0.5 * (tp + tm) - t);
  const double safety = 0.55;  // pixels: the edge ramp is ±0.5 px
  return {canvas.fx * x / z + canvas.cx, canvas.fy * y / z + canvas.cy, fMin * (r / d) - delta - safety,
          fMax * (tp - t) + safety, true};
}

}  // namespace

const std::vector<std::uint8_t>& SphereCuller::cull(const std::vector<CameraSphere>& spheres,
                                                    const std::vector<std::uint32_t>& order, const Canvas& canvas) {
  const int w = canvas.width, h = canvas.height;
  marked_.assign(static_cast<std::size_t>(w) * h, std::numeric_limits<float>::infinity());
  visible_.assign(spheres.size(), 1);
  for (std::uint32_t i : order) {
    const CameraSphere& s = spheres[i];
    const Footprint f = footprint(s, canvas);
    if (!f.valid) continue;
    // Hidden if every pixel centre within `outer` is marked by something wholly in front.
    const float nearest = s.z - s.radius;
    const int j0 = std::max(0, static_cast<int>(std::ceil(f.v - f.outer)));
    const int j1 = std::min(h - 1, static_cast<int>(std::floor(f.v + f.outer)));
    bool hidden = true;
    for (int j = j0; j <= j1 && hidden; ++j) {
      const double dy = j - f.v, half = std::sqrt(std::max(0.0, f.outer * f.outer - dy * dy));
      const int i0 = std::max(0, static_cast<int>(std::ceil(f.u - half)));
      const int i1 = std::min(w - 1, static_cast<int>(std::floor(f.u + half)));
      const float* row = marked_.data() + static_cast<std::size_t>(j) * w;
      for (int k = i0; k <= i1; ++k)
        if (!(row[k] < nearest)) {
          hidden = false;
          break;
        }
    }
    if (hidden) {
      visible_[i] = 0;
      continue;
    }
    // Mark the pixels it surely covers with its farthest depth.
    if (f.inner <= 0.0) continue;
    const float farthest = s.z + s.radius;
    const int m0 = std::max(0, static_cast<int>(std::ceil(f.v - f.inner)));
    const int m1 = std::min(h - 1, static_cast<int>(std::floor(f.v + f.inner)));
    for (int j = m0; j <= m1; ++j) {
      const double dy = j - f.v, half = std::sqrt(std::max(0.0, f.inner * f.inner - dy * dy));
      const int i0 = std::max(0, static_cast<int>(std::ceil(f.u - half)));
      const int i1 = std::min(w - 1, static_cast<int>(std::floor(f.u + half)));
      float* row = marked_.data() + static_cast<std::size_t>(j) * w;
      for (int k = i0; k <= i1; ++k) row[k] = std::min(row[k], farthest);
    }
  }
  return visible_;
}

}  // namespace rocklab::render::detail
