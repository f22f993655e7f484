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

class SphereCuller {
 public:
  /// `order` lists indices into `spheres` near to far. Returns visible[i] for each sphere.
  const std::vector<std::uint8_t>& cull(const std::vector<CameraSphere>& spheres, const std::vector<std::uint32_t>& order,
                                        const Canvas& canvas);

 private:
  std::vector<float> marked_;  // per canvas pixel: depth behind which everything is hidden (m), +inf unmarked
  std::vector<std::uint8_t> visible_;
};

}  // namespace rocklab::render::detail
