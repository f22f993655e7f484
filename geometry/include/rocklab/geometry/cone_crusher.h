#pragma once
// Cone-crusher chamber (experiments.md §g.1-g.2: Table 6.1, Eq 6-1..6-8): the
// derived radii, lengths and frustum end centres, and the walls as triangle meshes.
//
// Frame: the reference works in a vertical section with y up and x through the
// closed side; rocklab's gravity is -z, so its (x, y) is rocklab's (x, z): the
// crusher axis is the z axis through the origin, the closed side is +x at t = 0,
// and the section is the plane y = 0. y = 0 (rocklab z = 0) is the height of the
// concave's reference (O_bot_c sits CSS cos(alpha - gamma) above it, Eq 6-4).
//
// Readings where the reference is ambiguous ([X]/[R], each a setting):
//  - mantle_top_x: O_top_m's x as [R]-corrected, R_top_c - F sin(alpha-gamma) -
//    cos(gamma) R_top_m (~1.1 mm; the default), or as printed, R_top_c - cos(gamma) R_top_m.
//  - pivot: (A) Eq 6-2..6-8 as printed, the mantle's bottom centre s cos(gamma)
//    off the axis and the pivot at h = s / sin(gamma) on the crusher axis (the
//    default); (B) Eq 6-1's h = (s/2)/gamma_rad with the bottom centre s/2 off the
//    axis (e = s/2 in place of s in Eq 6-4, 6-7 and O_bot_m).
#include <stdexcept>
#include <string>

#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

enum class MantleTopX { Corrected, Printed };
enum class PivotPlacement { AxisPivot /* (A) */, Eq61 /* (B) */ };

/// Table 6.1, SI, angles in degrees; the baseline by default (CSS 15 mm, beta 20 deg).
struct ConeCrusherSpec {
  double feed_opening = 0.055;        // m   F, width of the feed opening
  double css = 0.015;                 // m   CSS, closed-side setting
  double throw_ = 0.0045;             // m   s, eccentric travel in half a revolution
  double bite_angle_deg = 20.0;       // deg beta, between concave and mantle
  double cone_angle_deg = 45.0;       // deg alpha, at the base of the mantle
  double eccentric_angle_deg = 2.0;   // deg gamma, tilt of the mantle axis
  double parallel_length = 0.050;     // m   delta_l, lower concave parallel to the mantle
  double mantle_diameter = 0.300;     // m   D_c, bottom diameter of the mantle
  MantleTopX mantle_top_x = MantleTopX::Corrected;
  PivotPlacement pivot = PivotPlacement::AxisPivot;
  int segments = 96;                  // -   mesh triangles around each frustum (x 2)
};

/// A bad spec: `parameter` is the field (as the scene key names it: "css",
/// "bite_angle_deg", ...) and what() says its value and what is allowed.
struct ConeCrusherError : std::invalid_argument {
  ConeCrusherError(std::string parameter_name, const std::string& message)
      : std::invalid_argument(message), parameter(std::move(parameter_name)) {}
  std::string parameter;
};

/// A point of the closed-side section: x radial (closed side), y up (rocklab z).
struct SectionPoint {
  double x = 0, y = 0;  // m
  Vec3 world() const { return {x, 0.0, y}; }
};

/// A gap of the section: from a point of the mantle to a point of the concave.
struct SectionGap {
  SectionPoint mantle, concave;
  double width = 0;  // m
};

/// Every derived quantity, in metres and radians unless named _deg.
struct ConeCrusherGeometry {
  ConeCrusherSpec spec;
  double bottom_offset = 0;    // m  e: mantle bottom centre off the axis, s in (A), s/2 in (B)
  double h_eq61 = 0;           // m  Eq 6-1: (s/2)/gamma_rad
  double pivot_distance = 0;   // m  h of the chosen placement: s/sin(gamma) (A), Eq 6-1 (B)
  double l_upper_c = 0;        // m  Eq 6-2
  double R_bot_m = 0;          // m  Eq 6-3
  double R_bot_c = 0;          // m  Eq 6-4
  double R_mid_c = 0;          // m  Eq 6-5
  double R_top_c = 0;          // m  Eq 6-6
  double R_top_m = 0;          // m  Eq 6-7
  double l_m = 0;              // m  Eq 6-8 (as printed: (F - CSS)/sin(beta), the upper concave's length)
  SectionPoint O_bot_c, O_mid_c, O_top_c, O_bot_m, O_top_m;  // frustum end centres
  double O_top_m_x_printed = 0;    // m  O_top_m's x as printed
  double O_top_m_x_corrected = 0;  // m  O_top_m's x as [R]-corrected
  SectionPoint pivot;          // on the crusher axis, pivot_distance above O_bot_m along gamma
  Vec3 mantle_axis = Vec3::UnitZ();  // unit, O_bot_m -> O_top_m (rocklab frame, t = 0)
  double mantle_tilt = 0;      // rad  of mantle_axis from the vertical (~1.8 deg at the baseline)
  double mantle_generator_length = 0;  // m  closed-side bottom edge to top edge
  SectionPoint mantle_bottom_edge, mantle_top_edge;  // closed side (t = 0)
  // Gaps measured on the built section: the smallest closed-side gap between mantle
  // and lower concave at t = 0 (the CSS the chamber really has), and the open-side
  // setting, from the lower concave's bottom lip to the mantle half a gyration later.
  double closed_side_gap = 0;  // m
  SectionGap closed_gap, open_gap;  // where they are measured
  SectionPoint open_mantle_bottom_edge, open_mantle_top_edge;  // closed-side section half a gyration later
  double open_side_setting = 0;  // m
};

/// Validates the spec and derives everything; throws ConeCrusherError.
ConeCrusherGeometry coneCrusherGeometry(const ConeCrusherSpec& spec);

/// The chamber's walls at t = 0 (rocklab frame), normals facing the chamber:
/// mantle and cap away from the axis, concaves toward it.
struct ConeCrusherMeshes {
  TriangleMesh mantle, lower_concave, upper_concave, mantle_cap;
};
/// The cap closes the mantle top with a cone continuing the mantle's slope alpha.
ConeCrusherMeshes coneCrusherMeshes(const ConeCrusherGeometry& g);

/// Apex of the cap: on the mantle axis, R_top_m tan(alpha) above O_top_m.
Vec3 mantleCapApex(const ConeCrusherGeometry& g);

const char* toString(MantleTopX v);      // "corrected" | "printed"
const char* toString(PivotPlacement v);  // "axis" | "eq6-1"

}  // namespace rocklab::geometry
