#pragma once
// The sphere externally tangent to four given spheres (the Apollonius problem in 3-D),
// the step of the dense random packing that fills a tetrahedral void
// (experiments.md §f.4 step 3, Eq 5-6…5-10).
#include <array>
#include <optional>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry {

enum class TangentFailure {
  None,            // a sphere was found
  Degenerate,      // the four centres are (nearly) coplanar: Eq 5-10 is singular
  NoPositiveRoot,  // the quadratic in r has no positive root
  CentreOutside,   // every positive root puts the centre outside the tetrahedron
};

/// One sentence for a failure ("the four centres are coplanar ..."), for reports.
const char* describe(TangentFailure failure);

struct TangentSolution {
  std::optional<Sphere> sphere;  // the inner tangent sphere, or nullopt
  TangentFailure failure = TangentFailure::None;
};

/// The inner tangent sphere of a group of four spheres: the smallest positive
/// radius r whose centre lies inside the tetrahedron of the four centres, with
/// |c − c_k| = r + r_k for k = 1…4. Solved as Eq 5-10 (linear in x, y, z with r as
/// a parameter, in coordinates relative to centre 1 against cancellation), then
/// Eq 5-6 as a quadratic in r. Groups whose Eq 5-10 matrix has |det| below 1e-9 of
/// the product of its row lengths (edges from centre 1) are Degenerate. Throws
/// std::invalid_argument for a radius <= 0 or a non-finite centre.
TangentSolution innerTangentSphere(const std::array<Sphere, 4>& group);

}  // namespace rocklab::geometry
