#include <algorithm>
#include <array>
#include <cstdint>

#include <opencv2/imgproc.hpp>

#include "detect_internal.h"

namespace rocklab::track::detail {

namespace {

// OpenCV's 8-bit BGR → HSV (imgproc, color_hsv: fixed point with 12 fraction bits
// and rounded reciprocal tables), written out so that the red test needs no HSV
// image: V = max, S = round(255 (V − min) / V), H = 30 (G − B) / (V − min) when V = R
// (+180 when negative), 30 (2 + (B − R) / (V − min)) when V = G, else
// 30 (4 + (R − G) / (V − min)); each quotient rounded exactly as OpenCV rounds it.
constexpr int kShift = 12;
constexpr int kHalf = 1 << (kShift - 1);

struct Reciprocals {
  std::array<int, 256> saturation{};  // round(255 · 2^12 / v)
  std::array<int, 256> hue{};         // round(180 · 2^12 / (6 d))
  Reciprocals() {
    for (int i = 1; i < 256; ++i) {
      saturation[static_cast<std::size_t>(i)] = cvRound((255 << kShift) / (1.0 * i));
      hue[static_cast<std::size_t>(i)] = cvRound((180 << kShift) / (6.0 * i));
    }
  }
};

const Reciprocals& reciprocals() {
  static const Reciprocals tables;
  return tables;
}

// The exact test: the pixel's OpenCV HSV inside one of the two red bands.
bool exactlyRed(int b, int g, int r, const DetectorSettings& s, const Reciprocals& q) {
  const int v = std::max({b, g, r}), diff = v - std::min({b, g, r});
  if (v < s.value_min) return false;
  const int saturation = (diff * q.saturation[static_cast<std::size_t>(v)] + kHalf) >> kShift;
  if (saturation < s.saturation_min) return false;
  int h = v == r ? g - b : v == g ? b - r + 2 * diff : r - g + 4 * diff;
  h = (h * q.hue[static_cast<std::size_t>(diff)] + kHalf) >> kShift;  // arithmetic shift: floor, as OpenCV
  if (h < 0) h += 180;
  return h <= s.hue_low_max || h >= s.hue_high_min;  // H never exceeds 179
}

// The candidate test, a superset of exactlyRed, in plain integer arithmetic with
// no table so that the compiler vectorises the loop over a row:
//   V ≥ value_min;
//   S ≥ saturation_min ⇒ 255 diff + ⌊V/2⌋ + 8 ≥ saturation_min · V (the reciprocal is
//     within ½ of 255 · 2^12 / V, which moves 255 diff by at most diff · V / 2^13 < 8,
//     and the rounding of S by at most V/2);
//   when both bands lie within 30 of red (H < 30 or H > 150), V = R: the other two
//     hue branches give H in [30, 150].
// Only candidates get the exact test (in the test scenes a few percent of the pixels).
// The loop vectorises where the target can de-interleave bytes (SSSE3 shuffles);
// on x86-64, whose baseline (SSE2) cannot, the compiler makes an AVX2, an SSSE3 and
// a plain copy and the loader picks the one the CPU runs.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target_clones("avx2", "ssse3", "default")))
#endif
bool candidates(const std::uint8_t* __restrict bgr, std::uint8_t* __restrict out, int width, int value_min,
                int saturation_min, bool red_max_only) {
  // 16-bit lanes: 255 diff + V/2 + 8 ≤ 65,160 and saturation_min · V ≤ 65,025.
  const auto v_min = static_cast<std::uint16_t>(value_min), s_min = static_cast<std::uint16_t>(saturation_min);
  std::uint8_t any = 0;
  for (int u = 0; u < width; ++u) {
    const std::uint16_t b = bgr[3 * u], g = bgr[3 * u + 1], r = bgr[3 * u + 2];
    const std::uint16_t v = std::max(std::max(b, g), r), diff = v - std::min(std::min(b, g), r);
    const bool bright = v >= v_min;
    const bool saturated = static_cast<std::uint16_t>(255 * diff + (v >> 1) + 8) >= static_cast<std::uint16_t>(s_min * v);
    const bool hue_possible = !red_max_only || v == r;
    out[u] = (bright && saturated && hue_possible) ? 255 : 0;
    any |= out[u];
  }
  return any != 0;
}

}  // namespace

cv::Mat redPixels(const cv::Mat& bgr, const DetectorSettings& s, cv::Range& rows) {
  CV_Assert(bgr.type() == CV_8UC3);
  const Reciprocals& q = reciprocals();
  const bool red_max_only = s.hue_low_max < 30 && s.hue_high_min > 150;
  cv::Mat mask(bgr.size(), CV_8U);
  rows = cv::Range(bgr.rows, 0);
  for (int v = 0; v < bgr.rows; ++v) {
    const std::uint8_t* in = bgr.ptr<std::uint8_t>(v);
    std::uint8_t* out = mask.ptr<std::uint8_t>(v);
    if (!candidates(in, out, bgr.cols, s.value_min, s.saturation_min, red_max_only)) continue;
    bool any = false;
    for (int u = nextNonzero(out, 0, bgr.cols); u < bgr.cols; u = nextNonzero(out, u + 1, bgr.cols)) {
      out[u] = exactlyRed(in[3 * u], in[3 * u + 1], in[3 * u + 2], s, q) ? 255 : 0;
      any = any || out[u];
    }
    if (any) rows = cv::Range(std::min(rows.start, v), v + 1);
  }
  if (rows.start >= rows.end) rows = cv::Range(0, 0);
  return mask;
}

cv::Mat redMask(const cv::Mat& bgr, const DetectorSettings& s, cv::Range& rows) {
  cv::Mat mask = redPixels(bgr, s, rows);
  // Open: erosion then dilation drops specks and one-pixel threads, keeps discs. It
  // cannot add a pixel, and what it does to a row depends only on the rows within
  // the kernel's side: it runs on the rows with red pixels and that margin (the
  // rows outside are zero before and after), as on the whole mask.
  if (s.open_kernel_px > 1 && !rows.empty()) {
    const int margin = s.open_kernel_px;
    const cv::Range band(std::max(0, rows.start - margin), std::min(mask.rows, rows.end + margin));
    cv::Mat part = mask.rowRange(band);
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(s.open_kernel_px, s.open_kernel_px));
    cv::morphologyEx(part, part, cv::MORPH_OPEN, kernel);
  }
  return mask;
}

}  // namespace rocklab::track::detail
