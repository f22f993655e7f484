#include "crusher/crusher_geometry_command.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"

namespace rocklab::experiments {

namespace {

using geometry::ConeCrusherGeometry;
using geometry::SectionPoint;

constexpr double kMm = 1e3;  // m -> mm
constexpr double kDeg = 180.0 / std::numbers::pi;

/// One printed and stored quantity, in the unit it is shown in.
struct Quantity {
  std::string key;   // results.json key (the unit is appended: R_bot_c_mm)
  double value;
  std::string unit;  // mm, deg, rad/s, rpm, -
  std::string what;
};

std::vector<Quantity> quantities(const ConeCrusherGeometry& g, const geometry::MantleMotion& m, double rpm) {
  const auto& s = g.spec;
  std::vector<Quantity> q = {
      {"F", s.feed_opening * kMm, "mm", "feed opening (Table 6.1)"},
      {"CSS", s.css * kMm, "mm", "closed-side setting, nominal (Table 6.1)"},
      {"s", s.throw_ * kMm, "mm", "throw (Table 6.1)"},
      {"beta", s.bite_angle_deg, "deg", "bite angle (Table 6.1)"},
      {"alpha", s.cone_angle_deg, "deg", "cone angle (Table 6.1)"},
      {"gamma", s.eccentric_angle_deg, "deg", "eccentric angle (Table 6.1)"},
      {"delta_l", s.parallel_length * kMm, "mm", "parallel length of the lower concave (Table 6.1)"},
      {"D_c", s.mantle_diameter * kMm, "mm", "mantle bottom diameter (Table 6.1)"},
      {"h_eq61", g.h_eq61 * kMm, "mm", "Eq 6-1: (s/2)/gamma_rad"},
      {"h", g.pivot_distance * kMm, "mm", "pivot distance of the chosen reading, O_bot_m to the pivot"},
      {"bottom_offset", g.bottom_offset * kMm, "mm", "e: mantle bottom centre off the axis (s in (A), s/2 in (B))"},
      {"l_upper_c", g.l_upper_c * kMm, "mm", "Eq 6-2: length of the upper concave"},
      {"l_m", g.l_m * kMm, "mm", "Eq 6-8: (F - CSS)/sin(beta), as printed"},
      {"R_bot_m", g.R_bot_m * kMm, "mm", "Eq 6-3: mantle bottom radius"},
      {"R_bot_c", g.R_bot_c * kMm, "mm", "Eq 6-4: lower concave bottom radius"},
      {"R_mid_c", g.R_mid_c * kMm, "mm", "Eq 6-5: lower concave top radius"},
      {"R_top_c", g.R_top_c * kMm, "mm", "Eq 6-6: upper concave top radius"},
      {"R_top_m", g.R_top_m * kMm, "mm", "Eq 6-7: mantle top radius"},
  };
  const std::pair<const char*, SectionPoint> points[] = {
      {"O_bot_c", g.O_bot_c}, {"O_mid_c", g.O_mid_c}, {"O_top_c", g.O_top_c},
      {"O_bot_m", g.O_bot_m}, {"O_top_m", g.O_top_m}, {"pivot", g.pivot},
      {"mantle_bottom_edge", g.mantle_bottom_edge}, {"mantle_top_edge", g.mantle_top_edge}};
  for (const auto& [name, p] : points) {
    q.push_back({std::string(name) + "_x", p.x * kMm, "mm", "section x (radial, closed side)"});
    q.push_back({std::string(name) + "_y", p.y * kMm, "mm", "section y (height; rocklab z)"});
  }
  const double net = m.eccentric_speed + m.signedSpin();
  q.insert(q.end(), {
      {"O_top_m_x_printed", g.O_top_m_x_printed * kMm, "mm", "O_top_m's x as printed"},
      {"O_top_m_x_corrected", g.O_top_m_x_corrected * kMm, "mm", "O_top_m's x as [R]-corrected"},
      {"mantle_tilt", g.mantle_tilt * kDeg, "deg", "mantle axis (O_bot_m to O_top_m) from the vertical"},
      {"mantle_generator_length", g.mantle_generator_length * kMm, "mm", "closed-side mantle generator, bottom to top edge"},
      {"closed_side_gap", g.closed_side_gap * kMm, "mm", "smallest mantle-concave gap at the closed side, measured"},
      {"open_side_setting", g.open_side_setting * kMm, "mm", "gap at the concave's bottom lip half a gyration later"},
      {"eccentric_speed", rpm, "rpm", "gyration about the crusher axis"},
      {"omega_ecc", m.eccentric_speed, "rad/s", "gyration"},
      {"omega_spin", m.spin_speed, "rad/s", "Eq 6-9: (R_bot_m + e)/R_bot_m omega_ecc"},
      {"net_mantle_rotation", net * 60 / (2 * std::numbers::pi), "rpm", "omega_ecc + signed spin about the mantle axis"},
  });
  return q;
}

std::string unitSuffix(const std::string& unit) {
  if (unit == "rad/s") return "rad_per_s";
  return unit == "-" ? "" : unit;
}

PlotSeries segment(const std::string& label, std::vector<SectionPoint> points) {
  PlotSeries s;
  s.label = label;
  s.style = PlotSeries::Style::Line;
  for (const SectionPoint& p : points) {
    s.x.push_back(p.x * kMm);
    s.y.push_back(p.y * kMm);
  }
  return s;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

/// The closed-side vertical section (x >= 0 and the axis), in mm, equal scales.
void drawSection(const ConeCrusherGeometry& g, const std::filesystem::path& png) {
  const SectionPoint apex{geometry::mantleCapApex(g).x(), geometry::mantleCapApex(g).z()};
  PlotSpec plot;
  plot.title = "Cone crusher, closed-side section (CSS " + fixed(g.spec.css * kMm, 1) + " mm, beta " +
               fixed(g.spec.bite_angle_deg, 1) + " deg, pivot " + geometry::toString(g.spec.pivot) + ")";
  plot.x_label = "x, radial through the closed side (mm)";
  plot.y_label = "height (mm)";
  const SectionPoint lip{g.R_bot_c, g.O_bot_c.y};
  plot.series = {
      segment("concave (lower, upper)", {lip, {g.R_mid_c, g.O_mid_c.y}, {g.R_top_c, g.O_top_c.y}}),
      segment("mantle and cap, t = 0", {g.O_bot_m, g.mantle_bottom_edge, g.mantle_top_edge, apex}),
      segment("mantle half a gyration later", {g.open_mantle_bottom_edge, g.open_mantle_top_edge}),
      segment("closed-side gap " + fixed(g.closed_side_gap * kMm, 2) + " mm (nominal CSS " +
                  fixed(g.spec.css * kMm, 2) + " mm)",
              {g.closed_gap.mantle, g.closed_gap.concave}),
      segment("open-side setting " + fixed(g.open_side_setting * kMm, 2) + " mm",
              {g.open_gap.mantle, g.open_gap.concave}),
      segment("mantle axis", {g.O_bot_m, apex}),
      segment("crusher axis", {{0, std::min(g.O_bot_m.y, g.open_mantle_bottom_edge.y)}, {0, g.O_top_c.y}}),
  };
  // Equal scales: the same span in mm on both axes of a square plot, with room
  // above the chamber and beside it for the legend.
  const double lo_y = std::min({g.O_bot_m.y, g.open_mantle_bottom_edge.y, 0.0}) * kMm - 10;
  const double span =
      std::max({g.R_bot_c * kMm + 20, g.O_top_c.y * kMm - lo_y + 10, apex.y * kMm - lo_y + 10}) + 60;
  plot.x_range = std::pair{-10.0, span - 10.0};
  plot.y_range = std::pair{lo_y, lo_y + span};
  plot.width = plot.height = 900;
  writePlot(plot, png);
}

}  // namespace

int runCrusherGeometry(const CrusherGeometryOptions& o, std::ostream& out, std::ostream& err) {
  Scene scene;
  try {
    scene = loadScene(resolveScene(o.scene), o.overrides);
  } catch (const SceneError& e) {
    err << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (!scene.crusher) {
    err << "error: crusher-geometry: " << scene.source.string()
        << " has no [crusher] table (the cone crusher's Table 6.1 keys; docs/crusher.md)\n";
    return kExitBadInput;
  }
  const CrusherSettings& c = *scene.crusher;
  const ConeCrusherGeometry g = geometry::coneCrusherGeometry(c.spec);  // checked by the reader
  const geometry::MantleMotion motion = geometry::mantleMotion(g, c.eccentric_rpm, c.spin_sense);
  const std::vector<Quantity> table = quantities(g, motion, c.eccentric_rpm);
  const std::filesystem::path dir =
      o.out_dir.empty() ? std::filesystem::path("out") / (scene.run.name + "-geometry") : o.out_dir;

  nlohmann::json results;
  results["scene"] = scene.run.name;
  results["source"] = scene.source.string();
  results["readings"] = {{"mantle_top_x", geometry::toString(c.spec.mantle_top_x)},
                         {"pivot", geometry::toString(c.spec.pivot)},
                         {"spin_sense", geometry::toString(c.spin_sense)}};
  for (const Quantity& q : table) {
    const std::string suffix = unitSuffix(q.unit);
    results["quantities"][q.key + (suffix.empty() ? "" : "_" + suffix)] = q.value;
  }
  const geometry::ConeCrusherMeshes meshes = geometry::coneCrusherMeshes(g);
  results["mesh_triangles"] = {{"mantle", meshes.mantle.triangleCount()},
                               {"mantle_cap", meshes.mantle_cap.triangleCount()},
                               {"lower_concave", meshes.lower_concave.triangleCount()},
                               {"upper_concave", meshes.upper_concave.triangleCount()}};
  results["section_png"] = "section.png";
  try {
    std::filesystem::create_directories(dir);
    drawSection(g, dir / "section.png");
    detail::writeAtomically(dir / "results.json", results.dump(2) + "\n");
  } catch (const std::exception& e) {
    err << "error: crusher-geometry: " << e.what() << "\n";
    return kExitBadInput;
  }

  out << "cone crusher of " << scene.source.string() << " (frame: z up, crusher axis z, closed side +x at t = 0)\n"
      << "readings: mantle_top_x = " << geometry::toString(c.spec.mantle_top_x)
      << ", pivot = " << geometry::toString(c.spec.pivot) << ", spin_sense = " << geometry::toString(c.spin_sense)
      << "\n";
  for (const Quantity& q : table)
    out << "  " << std::left << std::setw(26) << q.key << std::right << std::setw(12) << fixed(q.value, 3) << " "
        << std::left << std::setw(6) << q.unit << std::right << "  " << q.what << "\n";
  out << "wrote " << (dir / "section.png").string() << " and " << (dir / "results.json").string() << "\n";
  return kExitOk;
}

}  // namespace rocklab::experiments
