#pragma once
// Occlusion culling of spheres on the CPU, so hidden pebbles deep in a pile cost
// no fragment shading (llvmpipe shades every fragment of an impostor: writing
// gl_FragDepth turns off its early depth test).
//
// Spheres are visited near to far by their power |c|² − r² (for two disjoint
// spheres the eye lies on the nearer one's side of their radical plane, so this
// is their exact visibility order). Each visible sphere marks the pixels it surely
// covers opaquely with its largest depth z + r; a later sphere is dropped when
// every pixel it could touch is already marked by something wholly in front of
// it (marked depth < its smallest depth z − r). Interpenetrating spheres (clump
// members, contact overlaps) share depth ranges, so neither hides the other here:
// the depth buffer sorts them out.
//
// A sphere that stays is bounded by the pixels where it can still show: a pixel
// centre marked by something wholly in front is covered opaquely by that nearer
// sphere, drawn later (far to near), so shading it here changes nothing. Its
// drawn box shrinks to the rectangle of the pixels that are left.
#include <cstdint>
#include <vector>

#include "lens.h"

namespace rocklab::render::detail {

struct CameraSphere {
  float x, y, z;  // centre, camera frame, m
  float radius;   // m
};

// Image of a sphere around its projected centre (u, v): every pixel it touches
// (soft edge included) lies within `outer`; every pixel within `inner` is fully
// covered. With d = |c|, α = asin(r/d) and θ the angle of c off the optical axis,
// the image is an ellipse with radial ends at f tan(θ ± α) and semi-axes ≥ f sin α;
// the projected centre sits δ = f ((tan(θ+α) + tan(θ−α))/2 − tan θ) outward of the
// ellipse centre. Half a pixel more (less) for the antialiased edge ramp.
struct Footprint {  // pixels
  double u, v, inner, outer;
  bool valid;
};

// Pixels (inclusive, canvas coordinates) where a sphere may show; empty = hidden.
struct PixelRect {
  std::int32_t u0, v0, u1, v1;
  bool empty() const { return u0 > u1; }
  bool operator==(const PixelRect&) const = default;
};

class SphereCuller {
 public:
  /// `threads` bands of rows culled at once (0: the machine's cores, at most 8); the
  /// result does not depend on it.
  explicit SphereCuller(int threads = 0);
  /// `order` lists indices into `spheres` near to far. Returns, for each sphere, the
  /// rectangle of pixels where it may show (empty: hidden).
  const std::vector<PixelRect>& cull(const std::vector<CameraSphere>& spheres, const std::vector<std::uint32_t>& order,
                                        const Canvas& canvas);

 private:
  int threads_;
  std::vector<std::int16_t> marked_;  // per canvas pixel: depth step behind which everything is hidden
  std::vector<Footprint> footprints_;
  std::vector<std::vector<PixelRect>> bandRects_;  // per band of rows: where each shows there
  std::vector<PixelRect> rects_;
};

}  // namespace rocklab::render::detail
