#include "rocklab/geometry/cone_crusher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "rocklab/geometry/frustum_mesh.h"

namespace rocklab::geometry {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string mm(double metres) {
  std::ostringstream s;
  s << metres * 1e3 << " mm";
  return s.str();
}

std::string deg(double degrees) {
  std::ostringstream s;
  s << degrees << " deg";
  return s.str();
}

[[noreturn]] void refuse(const std::string& parameter, const std::string& what) {
  throw ConeCrusherError(parameter, "cone crusher: " + parameter + " " + what);
}

void requirePositiveLength(const std::string& parameter, const char* symbol, double v) {
  if (!(v > 0) || !std::isfinite(v))
    refuse(parameter, std::string("(") + symbol + ") = " + mm(v) + ": must be a finite length > 0");
}

void requireAngle(const std::string& parameter, const char* symbol, double v, double hi,
                  const std::string& hi_reason) {
  if (!(v > 0 && v < hi) || !std::isfinite(v))
    refuse(parameter, std::string("(") + symbol + ") = " + deg(v) + ": must be > 0 deg and < " + deg(hi) +
                          hi_reason);
}

void validateInputs(const ConeCrusherSpec& s) {
  requirePositiveLength("feed_opening", "F", s.feed_opening);
  requirePositiveLength("css", "CSS", s.css);
  if (!(s.css < s.feed_opening))
    refuse("css", "(CSS) = " + mm(s.css) + ": must be less than the feed opening F = " + mm(s.feed_opening) +
                      " (the chamber narrows from F down to CSS)");
  requirePositiveLength("throw", "s", s.throw_);
  requirePositiveLength("parallel_length", "delta_l", s.parallel_length);
  requirePositiveLength("mantle_diameter", "D_c", s.mantle_diameter);
  requireAngle("cone_angle_deg", "alpha", s.cone_angle_deg, 90, "");
  requireAngle("eccentric_angle_deg", "gamma", s.eccentric_angle_deg, s.cone_angle_deg,
               " (below the cone angle alpha: the closed-side mantle slopes at alpha - gamma)");
  requireAngle("bite_angle_deg", "beta", s.bite_angle_deg, 90, "");
  if (s.segments < 3)
    refuse("segments", "= " + std::to_string(s.segments) + ": must be >= 3 (triangles around each frustum)");
}

/// The point of the segment a-b nearest to p, in the section.
SectionPoint nearestOnSegment(SectionPoint p, SectionPoint a, SectionPoint b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return {a.x + t * dx, a.y + t * dy};
}

double distance(SectionPoint p, SectionPoint q) { return std::hypot(p.x - q.x, p.y - q.y); }

/// The nearest pair of two segments that do not cross: one end of one and its nearest point on the other.
SectionGap nearestPair(SectionPoint a0, SectionPoint a1, SectionPoint b0, SectionPoint b1) {
  SectionGap best;
  best.width = std::numeric_limits<double>::infinity();
  auto consider = [&](SectionPoint on_a, SectionPoint on_b) {
    if (const double d = distance(on_a, on_b); d < best.width) best = {on_a, on_b, d};
  };
  consider(a0, nearestOnSegment(a0, b0, b1));
  consider(a1, nearestOnSegment(a1, b0, b1));
  consider(nearestOnSegment(b0, a0, a1), b0);
  consider(nearestOnSegment(b1, a0, a1), b1);
  return best;
}

}  // namespace

const char* toString(MantleTopX v) { return v == MantleTopX::Corrected ? "corrected" : "printed"; }
const char* toString(PivotPlacement v) { return v == PivotPlacement::AxisPivot ? "axis" : "eq6-1"; }

ConeCrusherGeometry coneCrusherGeometry(const ConeCrusherSpec& spec) {
  validateInputs(spec);
  ConeCrusherGeometry g;
  g.spec = spec;
  const double F = spec.feed_opening, CSS = spec.css, s = spec.throw_, dl = spec.parallel_length;
  const double alpha = spec.cone_angle_deg * kDeg, beta = spec.bite_angle_deg * kDeg,
               gamma = spec.eccentric_angle_deg * kDeg;
  const double closed_slope = alpha - gamma;          // closed-side mantle generator to the horizontal
  const double upper_slope = alpha + beta - gamma;    // upper concave to the horizontal

  g.h_eq61 = (s / 2) / gamma;  // Eq 6-1: 180 s / (2 pi gamma_deg)
  const bool axis_pivot = spec.pivot == PivotPlacement::AxisPivot;
  g.bottom_offset = axis_pivot ? s : s / 2;
  g.pivot_distance = axis_pivot ? s / std::sin(gamma) : g.h_eq61;
  const double e = g.bottom_offset;

  g.l_upper_c = (F - CSS) / std::sin(beta);                                       // Eq 6-2
  g.R_bot_m = spec.mantle_diameter / 2;                                           // Eq 6-3
  g.R_bot_c = std::cos(gamma) * (e + g.R_bot_m) + CSS * std::sin(closed_slope);   // Eq 6-4
  g.R_mid_c = g.R_bot_c - dl * std::cos(closed_slope);                            // Eq 6-5
  g.R_top_c = g.R_mid_c - g.l_upper_c * std::cos(upper_slope);                    // Eq 6-6
  g.R_top_m = (g.R_top_c - std::sin(closed_slope) * F) / (std::cos(gamma) * (e + g.R_bot_m)) * g.R_bot_m;  // Eq 6-7
  g.l_m = (F - CSS) / std::sin(beta);                                             // Eq 6-8

  if (!(g.R_mid_c > 0))
    refuse("parallel_length", "(delta_l) = " + mm(dl) + " makes the lower concave's top radius R_mid_c = " +
                                  mm(g.R_mid_c) + " (Eq 6-5): must be > 0; shorten delta_l or widen D_c");
  if (!(g.R_top_c > 0))
    refuse("bite_angle_deg", "(beta) = " + deg(spec.bite_angle_deg) +
                                 " makes the upper concave's top radius R_top_c = " + mm(g.R_top_c) +
                                 " (Eq 6-6): must be > 0; use a larger bite angle or a smaller F - CSS");
  if (!(g.R_top_m > 0))
    refuse("feed_opening", "(F) = " + mm(F) + " makes the mantle's top radius R_top_m = " + mm(g.R_top_m) +
                               " (Eq 6-7): must be > 0; the chamber closes before the feed opening: use a "
                               "smaller F, a larger bite angle or a larger D_c");
  if (!(g.R_top_m < g.R_bot_m))
    refuse("bite_angle_deg", "(beta) = " + deg(spec.bite_angle_deg) + " makes the mantle's top radius R_top_m = " +
                                 mm(g.R_top_m) + " (Eq 6-7) no smaller than its bottom radius " + mm(g.R_bot_m) +
                                 ": the mantle must narrow upwards");

  // Frustum end centres (§g.2), section (x, y).
  const double y_mid = CSS * std::cos(closed_slope) + dl * std::sin(closed_slope);
  g.O_bot_c = {0, CSS * std::cos(closed_slope)};
  g.O_mid_c = {0, y_mid};
  g.O_top_c = {0, y_mid + std::sin(upper_slope) * g.l_m};
  g.O_bot_m = {e * std::cos(gamma), -e * std::sin(gamma)};
  g.O_top_m_x_printed = g.R_top_c - std::cos(gamma) * g.R_top_m;
  g.O_top_m_x_corrected = g.R_top_c - F * std::sin(closed_slope) - std::cos(gamma) * g.R_top_m;  // [R]
  g.O_top_m = {spec.mantle_top_x == MantleTopX::Corrected ? g.O_top_m_x_corrected : g.O_top_m_x_printed,
               (CSS - F) * std::cos(closed_slope) + dl * std::sin(closed_slope) + std::sin(upper_slope) * g.l_m -
                   std::sin(gamma) * g.R_top_m};
  g.pivot = {0, g.O_bot_m.y + g.pivot_distance * std::cos(gamma)};

  // The mantle as built: a right frustum between its end centres.
  const double ax = g.O_top_m.x - g.O_bot_m.x, ay = g.O_top_m.y - g.O_bot_m.y;
  if (!(ay > 0))
    refuse("feed_opening", "(F) = " + mm(F) + " puts the mantle's top centre " + mm(g.O_top_m.y) +
                               " high, not above its bottom centre " + mm(g.O_bot_m.y) + ": must be above");
  g.mantle_tilt = std::atan2(-ax, ay);
  g.mantle_axis = SectionPoint{ax, ay}.world().normalized();
  const double c = std::cos(g.mantle_tilt), sn = std::sin(g.mantle_tilt);  // (c, sn): closed-side radial of the discs
  g.mantle_bottom_edge = {g.O_bot_m.x + g.R_bot_m * c, g.O_bot_m.y + g.R_bot_m * sn};
  g.mantle_top_edge = {g.O_top_m.x + g.R_top_m * c, g.O_top_m.y + g.R_top_m * sn};
  g.mantle_generator_length = std::hypot(g.mantle_top_edge.x - g.mantle_bottom_edge.x,
                                         g.mantle_top_edge.y - g.mantle_bottom_edge.y);

  // Gaps in the section. Closed side (t = 0): the smallest distance between the
  // mantle's generator and the lower concave (the measured CSS). Open side (half a
  // gyration later the closed-side section shows t = 0's open side, mirrored in x):
  // from the lower concave's bottom lip to the mantle's generator (the discharge).
  const SectionPoint lip{g.R_bot_c, g.O_bot_c.y}, concave_top{g.R_mid_c, g.O_mid_c.y};
  g.closed_gap = nearestPair(g.mantle_bottom_edge, g.mantle_top_edge, lip, concave_top);
  const SectionPoint open_bottom{-(g.O_bot_m.x - g.R_bot_m * c), g.O_bot_m.y - g.R_bot_m * sn},
      open_top{-(g.O_top_m.x - g.R_top_m * c), g.O_top_m.y - g.R_top_m * sn};
  const SectionPoint open_foot = nearestOnSegment(lip, open_bottom, open_top);
  g.open_gap = {open_foot, lip, distance(open_foot, lip)};
  g.closed_side_gap = g.closed_gap.width;
  g.open_side_setting = g.open_gap.width;
  g.open_mantle_bottom_edge = open_bottom;
  g.open_mantle_top_edge = open_top;
  return g;
}

Vec3 mantleCapApex(const ConeCrusherGeometry& g) {
  return g.O_top_m.world() + g.R_top_m * std::tan(g.spec.cone_angle_deg * kDeg) * g.mantle_axis;
}

ConeCrusherMeshes coneCrusherMeshes(const ConeCrusherGeometry& g) {
  const int n = g.spec.segments;
  const Vec3 closed_radial(std::cos(g.mantle_tilt), 0, std::sin(g.mantle_tilt));  // perpendicular to the mantle axis
  ConeCrusherMeshes m;
  m.mantle = frustumMesh({g.O_bot_m.world(), g.O_top_m.world(), g.R_bot_m, g.R_top_m, closed_radial, n,
                          FrustumFacing::AwayFromAxis});
  m.mantle_cap = frustumMesh({g.O_top_m.world(), mantleCapApex(g), g.R_top_m, 0.0, closed_radial, n,
                              FrustumFacing::AwayFromAxis});
  m.lower_concave = frustumMesh({g.O_bot_c.world(), g.O_mid_c.world(), g.R_bot_c, g.R_mid_c, Vec3::UnitX(), n,
                                 FrustumFacing::TowardAxis});
  m.upper_concave = frustumMesh({g.O_mid_c.world(), g.O_top_c.world(), g.R_mid_c, g.R_top_c, Vec3::UnitX(), n,
                                 FrustumFacing::TowardAxis});
  return m;
}

}  // namespace rocklab::geometry
