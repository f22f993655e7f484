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

// Depths in the mark buffer are 16-bit steps between the nearest and the farthest
// point of the frame's spheres (a quarter of the float's memory per row, so a band's
// marks stay in the core's cache): a mark is rounded away from the eye, a sphere's
// nearest point towards it, and "marked in front" needs a whole step between them,
// so rounding can only keep a sphere, never drop one that shows.
using Mark = std::int16_t;
constexpr Mark kUnmarked = 32767;

struct DepthSteps {
  double zmin = 0, scale = 1;  // step = (z − zmin) scale − 32767
  Mark nearest(float z) const {  // rounded towards the eye
    return static_cast<Mark>(std::clamp(std::floor((z - zmin) * scale) - 32767.0, -32767.0, 32766.0));
  }
  Mark farthest(float z) const {  // rounded away from it
    return static_cast<Mark>(std::clamp(std::ceil((z - zmin) * scale) - 32767.0, -32767.0, 32766.0));
  }
};

// Rows of the mark buffer are kWindow marks longer than the canvas, never used: a
// row's pixels can then be read and written kWindow at a time from any pixel without
// touching another row (which may be another band's).
constexpr int kWindow = 16;

// Pixels i0 … i1 of one row (i0 ≤ i1): the first and the last whose mark is not in
// front of `nearest` (last < first when every one is hidden). A footprint's row is
// short (about 10 pixels at 640×480), so a fixed window of 16 without branches beats
// a loop whose length the CPU mispredicts.
Span unhidden(const Mark* row, int i0, int i1, Mark nearest) {
  int first = i1 + 1, last = i0 - 1;
  for (int k = i0; k <= i1; k += kWindow) {
    const int count = std::min(kWindow, i1 - k + 1);
    unsigned bits = 0;
#if defined(__SSE2__)
    const __m128i limit = _mm_set1_epi16(nearest);
    const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + k));
    const __m128i hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + k + 8));
    // Shown where the mark is not below `nearest`: the hidden lanes, packed to bytes, inverted.
    const __m128i hidden = _mm_packs_epi16(_mm_cmplt_epi16(lo, limit), _mm_cmplt_epi16(hi, limit));
    bits = ~static_cast<unsigned>(_mm_movemask_epi8(hidden)) & 0xffffu;
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
void mark(Mark* row, int i0, int i1, Mark depth) {
  for (int k = i0; k <= i1; k += kWindow) {
    const int count = std::min(kWindow, i1 - k + 1);
#if defined(__SSE2__)
    const __m128i value = _mm_set1_epi16(depth);
    for (int q = 0; q < kWindow / 8; ++q) {
      // Lanes 8q … 8q + 7 of the window that lie in the span take the smaller mark.
      const __m128i lane = _mm_setr_epi16(8 * q, 8 * q + 1, 8 * q + 2, 8 * q + 3, 8 * q + 4, 8 * q + 5, 8 * q + 6,
                                          8 * q + 7);
      const __m128i inside = _mm_cmplt_epi16(lane, _mm_set1_epi16(static_cast<short>(count)));
      __m128i* at = reinterpret_cast<__m128i*>(row + k + 8 * q);
      const __m128i old = _mm_loadu_si128(at);
      const __m128i lowered = _mm_min_epi16(old, value);
      _mm_storeu_si128(at, _mm_or_si128(_mm_and_si128(inside, lowered), _mm_andnot_si128(inside, old)));
    }
#else
    for (int q = 0; q < count; ++q) row[k + q] = std::min(row[k + q], depth);
#endif
  }
}

// The canvas columns whose pixel centres lie within [u − half, u + half] (first >
// last when none). Ceil and floor by truncating numbers ≥ 0: x86-64's baseline
// (SSE2) has no rounding instruction.
std::pair<int, int> columns(float u, float half, int w) {
  const float lo = std::clamp(u - half, -1.0f, static_cast<float>(w)) + 1.0f;  // ≥ 0
  const float hi = std::clamp(u + half, -1.0f, static_cast<float>(w)) + 1.0f;
  const int t = static_cast<int>(lo);
  const int first = t + (static_cast<float>(t) < lo ? 1 : 0) - 1;  // ceil(u − half)
  const int last = static_cast<int>(hi) - 1;                        // floor(u + half)
  return {std::max(0, first), std::min(w - 1, last)};
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
              const std::vector<Footprint>& footprints, const DepthSteps& steps, int w, int row0, int row1,
              Mark* marked, PixelRect* rects) {
  const std::size_t stride = static_cast<std::size_t>(w) + kWindow;
  std::fill(marked + row0 * stride, marked + row1 * stride, kUnmarked);
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
    const Mark nearest = steps.nearest(s.z - s.radius), farthest = steps.farthest(s.z + s.radius);
    // Rows in float: a footprint is a few pixels across and the margins are 0.05 pixel.
    const float u = static_cast<float>(f.u), v = static_cast<float>(f.v);
    const float outer2 = static_cast<float>(f.outer * f.outer);
    const float inner2 = f.inner > 0.0 ? static_cast<float>(f.inner * f.inner) : -1.0f;
    const int j0 = std::max(row0, static_cast<int>(std::ceil(f.v - f.outer)));
    const int j1 = std::min(row1 - 1, static_cast<int>(std::floor(f.v + f.outer)));
    PixelRect shows = kEmpty;
    for (int j = j0; j <= j1; ++j) {
      Mark* row = marked + j * stride;
      const float dy2 = (static_cast<float>(j) - v) * (static_cast<float>(j) - v);
      const auto [i0, i1] = columns(u, std::sqrt(std::max(0.0f, outer2 - dy2)), w);
      if (i0 > i1) continue;
      const Span span = unhidden(row, i0, i1, nearest);
      if (span.first <= span.last) shows = unite(shows, {span.first, j, span.last, j});
      if (dy2 >= inner2) continue;
      const auto [m0, m1] = columns(u, std::sqrt(inner2 - dy2), w);
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
  // The depth steps span the spheres' depths (a mark is a sphere's farthest point).
  float zmin = std::numeric_limits<float>::infinity(), zmax = -zmin;
  for (const CameraSphere& s : spheres) {
    zmin = std::min(zmin, s.z - s.radius);
    zmax = std::max(zmax, s.z + s.radius);
  }
  DepthSteps steps;
  if (zmax > zmin) steps = {zmin, 65533.0 / (static_cast<double>(zmax) - zmin)};
  runBands(bands, [&](int b) {
    cullBand(spheres, order, footprints_, steps, w, h * b / bands, h * (b + 1) / bands, marked_.data(),
             bandRects_[static_cast<std::size_t>(b)].data());
  });
  rects_ = bandRects_[0];
  for (std::size_t b = 1; b < bandRects_.size(); ++b)
    for (std::size_t i = 0; i < rects_.size(); ++i) rects_[i] = unite(rects_[i], bandRects_[b][i]);
  return rects_;
}

}  // namespace rocklab::render::detail
