#include "screen_layer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rocklab::render::detail {

ScreenLayer::ScreenLayer(const GlApi& gl, int width, int height)
    : gl_(gl), layer_(gl, width, height, 0, GL_RGBA32F) {}

void ScreenLayer::update(const std::vector<double>& key, const Framebuffer& opaque, const SurfacePass& surfaces,
                         const ViewUniforms& view) {
  if (key == key_) return;
  opaque.blitTo(layer_, GL_DEPTH_BUFFER_BIT);
  layer_.bindForDrawing();
  gl_.ClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  gl_.Clear(GL_COLOR_BUFFER_BIT);
  gl_.Enable(GL_DEPTH_TEST);
  gl_.DepthFunc(GL_LESS);
  gl_.DepthMask(GL_FALSE);
  gl_.Enable(GL_BLEND);
  // Colour: α L + (1 − α) C; coverage: α + (1 − α) A. The surface shader clamps L to
  // [0, 1] as an 8-bit target would.
  gl_.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  surfaces.drawTransparent(view);
  gl_.DepthMask(GL_TRUE);
  cv::Mat rgba;
  layer_.read(rgba);
  const std::size_t channels = 4 * rgba.total();
  keep_.resize(channels);
  add_.resize(channels);
  const double one = 1 << kFractionBits;
  const auto* in = rgba.ptr<float>();
  for (std::size_t i = 0; i < channels; i += 4) {
    const double keep = std::clamp(1.0 - in[i + 3], 0.0, 1.0);
    for (std::size_t c = 0; c < 3; ++c) {
      keep_[i + c] = static_cast<std::uint16_t>(std::lround(one * keep));
      // With the rounding (half a step); capped so that keep × 255 + add fits 16 bits
      // (C ≤ A makes the exact sum at most 255 levels: the cap takes off rounding only).
      const long add = std::lround(one * 255.0 * std::clamp(static_cast<double>(in[i + c]), 0.0, 1.0)) +
                       static_cast<long>(one / 2);
      add_[i + c] = static_cast<std::uint16_t>(std::min(add, 65535L - 255L * keep_[i + c]));
    }
    keep_[i + 3] = static_cast<std::uint16_t>(one);  // alpha stays
    add_[i + 3] = 0;
  }
  key_ = key;
}

void ScreenLayer::composite(cv::Mat& rgba) const {
  CV_Assert(rgba.type() == CV_8UC4 && rgba.isContinuous() && 4 * rgba.total() == keep_.size());
  std::uint8_t* out = rgba.ptr<std::uint8_t>();
  const std::uint16_t* keep = keep_.data();
  const std::uint16_t* add = add_.data();
  const std::size_t n = keep_.size();
  std::size_t i = 0;
#if defined(__SSE2__)
  // 16 channels at a time in 16-bit lanes: keep × in + add never exceeds 65535 (update()).
  const __m128i zero = _mm_setzero_si128();
  for (; i + 16 <= n; i += 16) {
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(out + i));
    const auto blend = [&](__m128i lanes, std::size_t at) {
      const __m128i k = _mm_loadu_si128(reinterpret_cast<const __m128i*>(keep + at));
      const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(add + at));
      return _mm_srli_epi16(_mm_add_epi16(_mm_mullo_epi16(lanes, k), a), kFractionBits);
    };
    const __m128i lo = blend(_mm_unpacklo_epi8(bytes, zero), i);
    const __m128i hi = blend(_mm_unpackhi_epi8(bytes, zero), i + 8);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm_packus_epi16(lo, hi));
  }
#endif
  for (; i < n; ++i)
    out[i] = static_cast<std::uint8_t>((static_cast<unsigned>(keep[i]) * out[i] + add[i]) >> kFractionBits);
}

}  // namespace rocklab::render::detail
