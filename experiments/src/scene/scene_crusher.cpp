// Scene reader: [crusher], the cone crusher of experiments.md §g (Table 6.1 keys,
// the readings of its ambiguities, the mantle speed and spin sense). The chamber
// is derived and checked by geometry::coneCrusherGeometry; its walls are appended
// to the model as mesh walls, the mantle and its cap moving (gyration + spin).
#include <algorithm>

#include "rocklab/geometry/frustum_mesh.h"
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

constexpr double kMaxAngle = 90.0;

// How the crusher's walls are drawn (a camera's view; [crusher] mantle_colour and
// concave_colour): the mantle and its cap a blue steel, the concave a bronze liner,
// the feed bin and the stop wall a dark steel, all apart from the grey rock.
constexpr render::Rgb kMantleColour{0.30f, 0.42f, 0.62f};
constexpr render::Rgb kConcaveColour{0.66f, 0.50f, 0.30f};
constexpr render::Rgb kFeedWallColour{0.34f, 0.36f, 0.38f};

geometry::ConeCrusherSpec readSpec(TableReader& t) {
  geometry::ConeCrusherSpec s;
  const Range open_angle{0.0, kMaxAngle, true, true};
  s.feed_opening = t.number("feed_opening", s.feed_opening, Range::positive());
  s.css = t.number("css", s.css, Range::positive());
  s.throw_ = t.number("throw", s.throw_, Range::positive());
  s.bite_angle_deg = t.number("bite_angle_deg", s.bite_angle_deg, open_angle);
  s.cone_angle_deg = t.number("cone_angle_deg", s.cone_angle_deg, open_angle);
  s.eccentric_angle_deg = t.number("eccentric_angle_deg", s.eccentric_angle_deg, open_angle);
  s.parallel_length = t.number("parallel_length", s.parallel_length, Range::positive());
  s.mantle_diameter = t.number("mantle_diameter", s.mantle_diameter, Range::positive());
  s.mantle_top_x = t.choice("mantle_top_x", s.mantle_top_x,
                            {{geometry::MantleTopX::Corrected, "corrected"}, {geometry::MantleTopX::Printed, "printed"}});
  s.pivot = t.choice("pivot", s.pivot,
                     {{geometry::PivotPlacement::AxisPivot, "axis"}, {geometry::PivotPlacement::Eq61, "eq6-1"}});
  s.segments = static_cast<int>(t.integer("segments", s.segments, Range::closed(3, 100000)));
  return s;
}

geometry::SpinSense parseSpinSense(const std::string& v) {
  if (v == "same") return geometry::SpinSense::Same;
  if (v == "none") return geometry::SpinSense::None;
  return geometry::SpinSense::Opposite;
}

/// The facets of a frustum of `segments` stand for a surface of revolution: their
/// creases (at most 360 / segments degrees) are smooth (sim::Wall::smooth_angle_deg).
double frustumSmoothAngleDeg(int segments) {
  return std::max(sim::Wall{}.smooth_angle_deg, 1.5 * 360.0 / segments);
}

void addWall(Scene& scene, int material, const std::string& name,
             const geometry::TriangleMesh& mesh, int segments, const WallLook& look,
             const sim::WallMotion& motion = {}) {
  sim::Wall w;
  w.name = name;
  w.shape = sim::WallShape::Mesh;
  w.mesh = mesh;
  w.smooth_angle_deg = frustumSmoothAngleDeg(segments);
  w.material = material;
  w.motion = motion;
  scene.model.walls.push_back(std::move(w));
  scene.wall_looks.push_back(look);
}

/// §g.4's temporary walls: the feed-bin cylinder (wall 1) above the chamber and the
/// flat stop wall (wall 2) the feed rests on until release_time, when it goes and
/// the feed falls into the chamber.
void addFeedWalls(TableReader& t, int material, const geometry::ConeCrusherGeometry& g, Scene& scene) {
  const double top_of_chamber = g.O_top_c.y;
  const double radius = t.number("feed_bin_radius", 0.07, Range::positive());
  const double stop = t.number("stop_height", top_of_chamber + 0.01, Range::positive());
  const double top = t.number("feed_bin_top", stop + 0.5, Range::positive());
  const double release = t.number("release_time", 0.5, Range::positive());
  if (!(radius < g.R_top_c))
    t.fail("feed_bin_radius", "must be less than the upper concave's top radius R_top_c = " +
                                  std::to_string(g.R_top_c * 1e3) + " mm (the feed must fall into the chamber)");
  if (!(stop > top_of_chamber))
    t.fail("stop_height", "must be above the chamber's top (O_top_c at " + std::to_string(top_of_chamber * 1e3) + " mm)");
  if (!(top > stop)) t.fail("feed_bin_top", "must be above stop_height");
  geometry::FrustumSpec bin;
  bin.bottom_centre = geometry::Vec3(0, 0, stop);
  bin.top_centre = geometry::Vec3(0, 0, top);
  bin.bottom_radius = bin.top_radius = radius;
  bin.segments = g.spec.segments;
  bin.facing = geometry::FrustumFacing::TowardAxis;
  WallLook bin_look;
  bin_look.colour = kFeedWallColour;
  addWall(scene, material, "crusher.feed_bin", geometry::frustumMesh(bin), bin.segments, bin_look);
  sim::Wall stop_wall;
  stop_wall.name = "crusher.stop";
  stop_wall.shape = sim::WallShape::Plane;
  stop_wall.point = geometry::Vec3(0, 0, stop);
  stop_wall.normal = geometry::Vec3::UnitZ();
  stop_wall.material = material;
  stop_wall.active_until = release;
  scene.model.walls.push_back(stop_wall);
  WallLook stop_look = bin_look;  // drawn as a disc filling the bin, not a 2 m square over the chamber
  stop_look.plane_disc = true;
  stop_look.plane_size = 2.0 * radius;
  scene.wall_looks.push_back(stop_look);
}

}  // namespace

sim::WallMotion mantleWallMotion(const geometry::MantleMotion& m) {
  sim::WallMotion w;
  w.angular_velocity = geometry::Vec3(0, 0, m.eccentric_speed);  // the gyration G(t) about the crusher axis
  w.pivot = geometry::Vec3::Zero();
  w.spin_rate = m.signedSpin();  // Eq 6-9, velocity only: the mantle maps onto itself
  w.spin_axis = m.axis;
  w.spin_point = m.axis_point;
  return w;
}

void readCrusher(TableReader& root, const std::map<std::string, int>& materials, Scene& scene) {
  auto t = root.table("crusher");
  if (!t) return;
  CrusherSettings c;
  c.spec = readSpec(*t);
  c.eccentric_rpm = t->number("eccentric_speed_rpm", c.eccentric_rpm, Range::nonNegative());
  c.spin_sense = parseSpinSense(t->string("spin_sense", "opposite", {"opposite", "same", "none"}));
  c.material = materialIndex(*t, materials);
  const bool walls = t->boolean("walls", true);
  WallLook mantle_look, concave_look;
  mantle_look.colour = readColour(*t, "mantle_colour", kMantleColour);
  concave_look.colour = readColour(*t, "concave_colour", kConcaveColour);
  geometry::ConeCrusherGeometry g;
  try {
    g = geometry::coneCrusherGeometry(c.spec);
  } catch (const geometry::ConeCrusherError& e) {
    t->fail(e.parameter, e.what());
  }
  if (walls) {
    const geometry::ConeCrusherMeshes m = geometry::coneCrusherMeshes(g);
    const sim::WallMotion mantle = mantleWallMotion(geometry::mantleMotion(g, c.eccentric_rpm, c.spin_sense));
    addWall(scene, c.material, "crusher.mantle", m.mantle, c.spec.segments, mantle_look, mantle);
    addWall(scene, c.material, "crusher.mantle_cap", m.mantle_cap, c.spec.segments, mantle_look,
            mantle);
    addWall(scene, c.material, "crusher.lower_concave", m.lower_concave, c.spec.segments,
            concave_look);
    addWall(scene, c.material, "crusher.upper_concave", m.upper_concave, c.spec.segments,
            concave_look);
  }
  if (t->boolean("feed_bin", false)) addFeedWalls(*t, c.material, g, scene);
  scene.crusher = c;
  t->finish();
}

}  // namespace rocklab::experiments::detail
