// Scene reader: [[walls]] (plane, polygon, plate, mesh, box), their motion and
// look.
#include <cmath>
#include <numbers>

#include "rocklab/geometry/mesh_import.h"
#include "rocklab/sim/wall_motion.h"
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

/// How a wall is drawn: colour, opacity, visible, and for an infinite plane
/// plane_size, plane_shape, plane_thickness (keys of [[walls]]).
WallLook readWallLook(TableReader& t) {
  WallLook look;
  look.colour = readColour(t, "colour", look.colour);
  look.opacity = static_cast<float>(t.number("opacity", look.opacity, Range::closed(0, 1)));
  look.visible = t.boolean("visible", look.visible);
  look.plane_size = t.number("plane_size", look.plane_size, Range::positive());
  look.plane_disc = t.string("plane_shape", "square", {"square", "disc"}) == "disc";
  look.plane_thickness = t.number("plane_thickness", look.plane_thickness, Range::nonNegative());
  return look;
}

void readMotion(TableReader& parent, sim::WallMotion& m) {
  auto t = parent.table("motion");
  if (!t) return;
  m.velocity = t->vec3("velocity", m.velocity);
  m.angular_velocity = t->vec3("angular_velocity", m.angular_velocity);
  m.pivot = t->vec3("pivot", m.pivot);
  m.amplitude = t->vec3("amplitude", m.amplitude);
  m.frequency = t->number("frequency", m.frequency, Range::nonNegative());
  t->finish();
}

}  // namespace

void readWalls(TableReader& root, const std::map<std::string, int>& materials,
               const std::filesystem::path& base_dir, sim::Model& model,
               std::vector<WallLook>& looks) {
  for (TableReader t : root.tableArray("walls")) {
    const WallLook look = readWallLook(t);
    const std::string type = t.requiredString("type", {"plane", "polygon", "plate", "mesh", "box"});
    const std::string name = t.string("name", t.path());
    sim::Wall w;
    w.name = name;
    w.material = materialIndex(t, materials);
    w.active_from = t.number("active_from", w.active_from);
    w.active_until = t.number("active_until", w.active_until);
    if (!(w.active_until > w.active_from)) t.fail("active_until", "must be after active_from");
    readMotion(t, w.motion);
    if (type == "plane") {
      w.shape = sim::WallShape::Plane;
      w.point = t.requiredVec3("point");
      w.normal = t.requiredVec3("normal");
      if (!(w.normal.norm() > 0)) t.fail("normal", "must not be the zero vector");
      if (!w.motion.angular_velocity.isZero(0))
        t.fail("motion", "an infinite plane cannot rotate; use type = \"polygon\"");
      model.walls.push_back(w);
    } else if (type == "polygon") {
      w.shape = sim::WallShape::Polygon;
      w.vertices = t.vec3List("vertices");
      if (const std::string problem = sim::polygonProblem(w.vertices); !problem.empty())
        t.fail("vertices", problem + " ([[x, y, z], ...])");
      model.walls.push_back(w);
    } else if (type == "plate") {
      // A rectangle from `corner`: `length` along x turned up by angle_deg
      // about y, `width` along y. The zoned chute's top plate: corner at the
      // CSS above the outlet, angle = bite angle (experiments.md §d).
      const Vec3 corner = t.requiredVec3("corner");
      const double length = t.requiredNumber("length", Range::positive());
      const double width = t.requiredNumber("width", Range::positive());
      const double angle =
          t.number("angle_deg", 0.0, Range::closed(-90, 90)) * std::numbers::pi / 180.0;
      const Vec3 along = length * Vec3(std::cos(angle), 0, std::sin(angle)), across(0, width, 0);
      w.shape = sim::WallShape::Polygon;
      w.vertices = {corner, corner + along, corner + along + across, corner + across};
      model.walls.push_back(w);
    } else if (type == "mesh") {
      w.shape = sim::WallShape::Mesh;
      const double scale = t.number("scale", 1.0, Range::positive());
      if (t.has("file")) {
        const std::filesystem::path file = base_dir / t.string("file", "");
        try {
          w.mesh = geometry::importMesh(file.string(), scale);
        } catch (const geometry::MeshImportError& e) {
          t.fail("file", e.what());
        }
      } else {
        w.mesh.vertices = t.vec3List("vertices");
        for (Vec3& v : w.mesh.vertices) v *= scale;
        w.mesh.triangles = t.indexTriples("triangles", w.mesh.vertices.size());
        if (w.mesh.triangles.empty())
          t.fail("triangles", "a mesh wall needs `file` or `vertices` + `triangles`");
      }
      const std::string msg = w.mesh.validate();
      if (!msg.empty()) t.fail(t.has("file") ? "file" : "triangles", msg);
      w.smooth_angle_deg =
          t.number("smooth_angle_deg", w.smooth_angle_deg, Range{0.0, 90.0, false, true});
      // After the scale: places a part in the scene, or moves one (one key raises
      // the heap's funnel).
      const Vec3 offset = t.vec3("offset", Vec3::Zero());
      for (Vec3& v : w.mesh.vertices) v += offset;
      model.walls.push_back(w);
    } else {  // box: five planes (open top) or six, facing inwards
      const Vec3 lo = t.requiredVec3("min"), hi = t.requiredVec3("max");
      if (!((hi - lo).minCoeff() > 0)) t.fail("max", "must exceed min in every component");
      const bool open_top = t.boolean("open_top", true);
      const std::pair<const char*, std::pair<Vec3, Vec3>> faces[] = {
          {"floor", {lo, Vec3::UnitZ()}}, {"xmin", {lo, Vec3::UnitX()}},
          {"xmax", {hi, -Vec3::UnitX()}}, {"ymin", {lo, Vec3::UnitY()}},
          {"ymax", {hi, -Vec3::UnitY()}}, {"top", {hi, -Vec3::UnitZ()}}};
      for (const auto& [face, pn] : faces) {
        if (open_top && std::string(face) == "top") continue;
        sim::Wall f = w;
        f.name = name + "." + face;
        f.shape = sim::WallShape::Plane;
        f.point = pn.first;
        f.normal = pn.second;
        model.walls.push_back(f);
      }
    }
    looks.resize(model.walls.size(),
                 look);  // a box adds several walls with one look
    t.finish();
  }
}

}  // namespace rocklab::experiments::detail
