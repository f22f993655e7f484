#include "sphere_culling.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "bands.h"

namespace rocklab::render::detail {

namespace {

Footprint footprint(const CameraSphere& s, const Canvas& canvas) {
  const double x = s.x, y = s.y, z = s.z, r = s.radius;
  const double d2 = x * x + y * y + z * z, d = std::sqrt(d2);
  const double fMin = std::min(canvas.fx, canvas.fy), fMax = std::max(canvas.fx, canvas.fy);
  // tan θ and tan α (θ off axis, α = asin(r/d) the half angle), then tan(θ ± α) by
  // the addition formula (z > r > 0: the near-plane test).
  const double t = std::sqrt(x * x + y * y) / z, ta = r / std::sqrt(d2 - r * r);
  const double below = 1.0 - t * ta;
  const double tanLimit = 8.238;  // tan 1.45: near 90° off axis there is no useful bound
  if (below <= 0.0 || t + ta > tanLimit * below) return {0, 0, 0, 0, false};
  const double tp = (t + ta) / below, tm = (t - ta) / (1.0 + t * ta);
  const double delta = fMax * std::abs(0.5 * (tp + tm) - t);
  const double safety = 0.55;  // pixels: the edge ramp is ±0.5 px
  return {canvas.fx * x / z + canvas.cx, canvas.fy * y / z + canvas.cy, fMin * (r / d) - delta - safety,
          fMax * (tp - t) + safety, true};
}

// Pixels i0 … i1 of one row: the first and last not hidden.
struct Span {
  int first, last;
};

// Rows of the mark buffer are kWindow floats longer than the canvas, never used: a
// row's pixels can then be read and written kWindow at a time from any pixel without
// touching another row (which may be another band's).
constexpr int kWindow = 16;

// Pixels i0 … i1 of one row (i0 ≤ i1): the first and the last whose mark is not in
// front of `nearest` (last < first when every one is hidden). A footprint's row is
// short (about 10 pixels at 640×480), so a fixed window of 16 without branches beats
// a loop whose length the CPU mispredicts.
Span unhidden(const float* row, int i0, int i1, float nearest) {
  int first = i1 + 1, last = i0 - 1;
  for (int k = i0; k <= i1; k += kWindow) {
    const int count = std::min(kWindow, i1 - k + 1);
    unsigned bits = 0;
#if defined(__SSE2__)
    const __m128 limit = _mm_set1_ps(nearest);
    for (int q = 0; q < kWindow / 4; ++q)
      bits |= static_cast<unsigned>(_mm_movemask_ps(_mm_cmpnlt_ps(_mm_loadu_ps(row + k + 4 * q), limit))) << (4 * q);
#else
    for (int q = 0; q < kWindow; ++q) bits |= static_cast<unsigned>(!(row[k + q] < nearest)) << q;
#endif
    bits &= (1u << count) - 1u;
    if (bits == 0) continue;
    first = std::min(first, k + std::countr_zero(bits));
    last = k + 31 - std::countl_zero(bits);
  }
  return {first, last};
}

// row[i0 … i1] = min(row, depth), i0 ≤ i1.
void mark(float* row, int i0, int i1, float depth) {
  for (int k = i0; k <= i1; k += kWindow) {
    const int count = std::min(kWindow, i1 - k + 1);
#if defined(__SSE2__)
    const __m128 value = _mm_set1_ps(depth);
    for (int q = 0; q < kWindow / 4; ++q) {
      // Lanes 4q … 4q + 3 of the window that lie in the span.
      const __m128i lane = _mm_setr_epi32(4 * q, 4 * q + 1, 4 * q + 2, 4 * q + 3);
      const __m128 inside = _mm_castsi128_ps(_mm_cmplt_epi32(lane, _mm_set1_epi32(count)));
      const __m128 old = _mm_loadu_ps(row + k + 4 * q);
      const __m128 lowered = _mm_min_ps(old, value);
      _mm_storeu_ps(row + k + 4 * q, _mm_or_ps(_mm_and_ps(inside, lowered), _mm_andnot_ps(inside, old)));
    }
#else
    for (int q = 0; q < count; ++q) row[k + q] = std::min(row[k + q], depth);
#endif
  }
}

constexpr PixelRect kEmpty{1, 1, 0, 0};

PixelRect unite(const PixelRect& a, const PixelRect& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.u0, b.u0), std::min(a.v0, b.v0), std::max(a.u1, b.u1), std::max(a.v1, b.v1)};
}

// One band of rows [row0, row1): every sphere in order, tested and marked on this
// band's pixels only. Bands share no pixels, so they run at once; the union of the
// bands' rectangles equals the whole-canvas cull exactly: marking a sphere that one
// band finds hidden changes nothing there (its pixels already hold nearer depths).
void cullBand(const std::vector<CameraSphere>& spheres, const std::vector<std::uint32_t>& order,
              const std::vector<Footprint>& footprints, int w, int row0, int row1, float* marked, PixelRect* rects) {
  const std::size_t stride = static_cast<std::size_t>(w) + kWindow;
  std::fill(marked + row0 * stride, marked + row1 * stride,
            std::numeric_limits<float>::infinity());
  for (std::size_t n = 0; n < order.size(); ++n) {
    const std::uint32_t i = order[n];
    const CameraSphere& s = spheres[i];
    const Footprint& f = footprints[i];
    if (!f.valid) {
      rects[i] = {0, row0, w - 1, row1 - 1};
      continue;
    }
    // The pixel centres within `outer` not marked by something wholly in front, and
    // the marks of the pixels it surely covers (within `inner`), with its farthest
    // depth, in one pass over its rows. Marking before the verdict changes nothing:
    // its own marks lie behind its nearest point, so they hide none of it, and if it
    // is hidden all of its pixels hold nearer marks already.
    const float nearest = s.z - s.radius, farthest = s.z + s.radius;
    const double outer2 = f.outer * f.outer, inner2 = f.inner > 0.0 ? f.inner * f.inner : -1.0;
    const int j0 = std::max(row0, static_cast<int>(std::ceil(f.v - f.outer)));
    const int j1 = std::min(row1 - 1, static_cast<int>(std::floor(f.v + f.outer)));
    PixelRect shows = kEmpty;
    for (int j = j0; j <= j1; ++j) {
      float* row = marked + j * stride;
      const double dy2 = (j - f.v) * (j - f.v);
      const double half = std::sqrt(std::max(0.0, outer2 - dy2));
      const int i0 = std::max(0, static_cast<int>(std::ceil(f.u - half)));
      const int i1 = std::min(w - 1, static_cast<int>(std::floor(f.u + half)));
      if (i0 > i1) continue;
      const Span span = unhidden(row, i0, i1, nearest);
      if (span.first <= span.last) shows = unite(shows, {span.first, j, span.last, j});
      if (dy2 >= inner2) continue;
      const double core = std::sqrt(inner2 - dy2);
      const int m0 = std::max(0, static_cast<int>(std::ceil(f.u - core)));
      const int m1 = std::min(w - 1, static_cast<int>(std::floor(f.u + core)));
      if (m0 <= m1) mark(row, m0, m1, farthest);
    }
    rects[i] = shows;
  }
}

}  // namespace

SphereCuller::SphereCuller(int threads) : threads_(bandCount(threads)) {}

const std::vector<PixelRect>& SphereCuller::cull(const std::vector<CameraSphere>& spheres,
                                                 const std::vector<std::uint32_t>& order, const Canvas& canvas) {
  const int w = canvas.width, h = canvas.height;
  // Bands of at least 32 rows: below that a thread costs more than it saves.
  const int bands = std::max(1, std::min(threads_, h / 32));
  marked_.resize((static_cast<std::size_t>(w) + kWindow) * h);
  footprints_.resize(spheres.size());
  bandRects_.resize(static_cast<std::size_t>(bands));
  for (auto& r : bandRects_) r.assign(spheres.size(), kEmpty);
  runBands(bands, [&](int b) {
    const std::size_t n = spheres.size(), first = n * b / bands, last = n * (b + 1) / bands;
    for (std::size_t i = first; i < last; ++i) footprints_[i] = footprint(spheres[i], canvas);
  });
  runBands(bands, [&](int b) {
    cullBand(spheres, order, footprints_, w, h * b / bands, h * (b + 1) / bands, marked_.data(),
             bandRects_[static_cast<std::size_t>(b)].data());
  });
  rects_ = bandRects_[0];
  for (std::size_t b = 1; b < bandRects_.size(); ++b)
    for (std::size_t i = 0; i < rects_.size(); ++i) rects_[i] = unite(rects_[i], bandRects_[b][i]);
  return rects_;
}

}  // namespace rocklab::render::detail
