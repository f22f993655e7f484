// Scene reader: [crusher], the cone crusher of experiments.md §g (Table 6.1 keys,
// the readings of its ambiguities, the mantle speed and spin sense). The chamber
// is derived and checked by geometry::coneCrusherGeometry; its walls are appended
// to the model as static mesh walls.
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

constexpr double kMaxAngle = 90.0;

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
  s.mantle_top_x = t.string("mantle_top_x", "corrected", {"corrected", "printed"}) == "printed"
                       ? geometry::MantleTopX::Printed
                       : geometry::MantleTopX::Corrected;
  s.pivot = t.string("pivot", "axis", {"axis", "eq6-1"}) == "eq6-1" ? geometry::PivotPlacement::Eq61
                                                                      : geometry::PivotPlacement::AxisPivot;
  s.segments = static_cast<int>(t.integer("segments", s.segments, Range::closed(3, 100000)));
  return s;
}

geometry::SpinSense parseSpinSense(const std::string& v) {
  if (v == "same") return geometry::SpinSense::Same;
  if (v == "none") return geometry::SpinSense::None;
  return geometry::SpinSense::Opposite;
}

void addWall(Scene& scene, int material, const std::string& name, const geometry::TriangleMesh& mesh,
             const WallLook& look) {
  sim::Wall w;
  w.name = name;
  w.shape = sim::WallShape::Mesh;
  w.mesh = mesh;
  w.material = material;
  scene.model.walls.push_back(std::move(w));
  scene.wall_looks.push_back(look);
}

}  // namespace

void readCrusher(TableReader& root, const std::map<std::string, int>& materials, Scene& scene) {
  auto t = root.table("crusher");
  if (!t) return;
  CrusherSettings c;
  c.spec = readSpec(*t);
  c.eccentric_rpm = t->number("eccentric_speed_rpm", c.eccentric_rpm, Range::nonNegative());
  c.spin_sense = parseSpinSense(t->string("spin_sense", "opposite", {"opposite", "same", "none"}));
  c.material = materialIndex(*t, materials);
  const bool walls = t->boolean("walls", true);
  geometry::ConeCrusherGeometry g;
  try {
    g = geometry::coneCrusherGeometry(c.spec);
  } catch (const geometry::ConeCrusherError& e) {
    t->fail(e.parameter, e.what());
  }
  if (walls) {
    const geometry::ConeCrusherMeshes m = geometry::coneCrusherMeshes(g);
    const WallLook look;
    addWall(scene, c.material, "crusher.mantle", m.mantle, look);
    addWall(scene, c.material, "crusher.mantle_cap", m.mantle_cap, look);
    addWall(scene, c.material, "crusher.lower_concave", m.lower_concave, look);
    addWall(scene, c.material, "crusher.upper_concave", m.upper_concave, look);
  }
  scene.crusher = c;
  t->finish();
}

}  // namespace rocklab::experiments::detail
