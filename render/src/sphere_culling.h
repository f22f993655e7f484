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

class SphereCuller {
 public:
  /// `threads` bands of rows culled at once (0: the machine's cores, at most 8); the
  /// result does not depend on it.
  explicit SphereCuller(int threads = 0);
  /// `order` lists indices into `spheres` near to far. Returns visible[i] for each sphere.
  const std::vector<std::uint8_t>& cull(const std::vector<CameraSphere>& spheres, const std::vector<std::uint32_t>& order,
                                        const Canvas& canvas);

 private:
  int threads_;
  std::vector<float> marked_;  // per canvas pixel: depth behind which everything is hidden (m), +inf unmarked
  std::vector<Footprint> footprints_;
  std::vector<std::vector<std::uint8_t>> bandVisible_;  // per band of rows: visible there
  std::vector<std::uint8_t> visible_;
};

}  // namespace rocklab::render::detail
