#include "sphere_culling.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bands.h"

namespace rocklab::render::detail {

namespace {

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

// One band of rows [row0, row1): every sphere in order, tested and marked on this
// band's pixels only. Bands share no pixels, so they run at once; the union of the
// bands' verdicts equals the whole-canvas cull exactly: marking a sphere that one
// band finds hidden changes nothing there (its pixels already hold nearer depths).
void cullBand(const std::vector<CameraSphere>& spheres, const std::vector<std::uint32_t>& order,
              const std::vector<Footprint>& footprints, int w, int row0, int row1, float* marked,
              std::uint8_t* visible) {
  std::fill(marked + static_cast<std::size_t>(row0) * w, marked + static_cast<std::size_t>(row1) * w,
            std::numeric_limits<float>::infinity());
  for (std::uint32_t i : order) {
    const CameraSphere& s = spheres[i];
    const Footprint& f = footprints[i];
    if (!f.valid) {
      visible[i] = 1;
      continue;
    }
    // Hidden (in this band) if every pixel centre within `outer` is marked by something wholly in front.
    const float nearest = s.z - s.radius;
    const int j0 = std::max(row0, static_cast<int>(std::ceil(f.v - f.outer)));
    const int j1 = std::min(row1 - 1, static_cast<int>(std::floor(f.v + f.outer)));
    bool hidden = true;
    for (int j = j0; j <= j1 && hidden; ++j) {
      const double dy = j - f.v, half = std::sqrt(std::max(0.0, f.outer * f.outer - dy * dy));
      const int i0 = std::max(0, static_cast<int>(std::ceil(f.u - half)));
      const int i1 = std::min(w - 1, static_cast<int>(std::floor(f.u + half)));
      // Branch-free within the row, so the compiler vectorises it: a hidden sphere scans
      // its whole footprint, and those are the costly ones.
      const float* row = marked + static_cast<std::size_t>(j) * w;
      int covered = 1;
      for (int k = i0; k <= i1; ++k) covered &= static_cast<int>(row[k] < nearest);
      hidden = covered != 0;
    }
    if (hidden) continue;
    visible[i] = 1;
    // Mark the pixels it surely covers with its farthest depth.
    if (f.inner <= 0.0) continue;
    const float farthest = s.z + s.radius;
    const int m0 = std::max(row0, static_cast<int>(std::ceil(f.v - f.inner)));
    const int m1 = std::min(row1 - 1, static_cast<int>(std::floor(f.v + f.inner)));
    for (int j = m0; j <= m1; ++j) {
      const double dy = j - f.v, half = std::sqrt(std::max(0.0, f.inner * f.inner - dy * dy));
      const int i0 = std::max(0, static_cast<int>(std::ceil(f.u - half)));
      const int i1 = std::min(w - 1, static_cast<int>(std::floor(f.u + half)));
      float* row = marked + static_cast<std::size_t>(j) * w;
      for (int k = i0; k <= i1; ++k) row[k] = std::min(row[k], farthest);
    }
  }
}

}  // namespace

SphereCuller::SphereCuller(int threads) : threads_(bandCount(threads)) {}

const std::vector<std::uint8_t>& SphereCuller::cull(const std::vector<CameraSphere>& spheres,
                                                    const std::vector<std::uint32_t>& order, const Canvas& canvas) {
  const int w = canvas.width, h = canvas.height;
  // Bands of at least 32 rows: below that a thread costs more than it saves.
  const int bands = std::max(1, std::min(threads_, h / 32));
  marked_.resize(static_cast<std::size_t>(w) * h);
  footprints_.resize(spheres.size());
  bandVisible_.resize(static_cast<std::size_t>(bands));
  for (auto& v : bandVisible_) v.assign(spheres.size(), 0);
  runBands(bands, [&](int b) {
    const std::size_t n = spheres.size(), first = n * b / bands, last = n * (b + 1) / bands;
    for (std::size_t i = first; i < last; ++i) footprints_[i] = footprint(spheres[i], canvas);
  });
  runBands(bands, [&](int b) {
    cullBand(spheres, order, footprints_, w, h * b / bands, h * (b + 1) / bands, marked_.data(),
             bandVisible_[static_cast<std::size_t>(b)].data());
  });
  visible_ = bandVisible_[0];
  for (std::size_t b = 1; b < bandVisible_.size(); ++b)
    for (std::size_t i = 0; i < visible_.size(); ++i) visible_[i] |= bandVisible_[b][i];
  return visible_;
}

}  // namespace rocklab::render::detail
