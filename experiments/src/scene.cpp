#include "rocklab/experiments/scene.h"

#include <fstream>
#include <map>
#include <sstream>

#include "rocklab/geometry/mesh_import.h"
#include "rocklab/geometry/packing.h"
#include "toml_reader.h"

#ifndef ROCKLAB_ASSET_DIR
#define ROCKLAB_ASSET_DIR "assets"
#endif

namespace rocklab::experiments {

using detail::Range;
using detail::TableReader;
using geometry::Vec3;

namespace {

const Range kFraction01 = Range::closed(0.0, 1.0);

sim::Material readMaterial(TableReader t, const std::string& name) {
  sim::Material m;
  m.name = name;
  m.density = t.number("density", m.density, Range::positive());
  m.kn = t.number("kn", m.kn, Range::nonNegative());
  m.ks = t.number("ks", m.kn, Range::nonNegative());  // defaults to kn
  m.friction = t.number("friction", m.friction, Range::nonNegative());
  m.shear_modulus = t.number("shear_modulus", m.shear_modulus, Range::nonNegative());
  m.poisson = t.number("poisson", m.poisson, {-1.0, 0.5, true, true});
  t.finish();
  return m;
}

int materialIndex(TableReader& t, const std::map<std::string, int>& materials) {
  std::vector<std::string> names;
  for (const auto& [n, i] : materials) names.push_back(n);
  return materials.at(t.requiredString("material", names));
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

void readWalls(TableReader& root, const std::map<std::string, int>& materials,
               const std::filesystem::path& base_dir, sim::Model& model) {
  for (TableReader t : root.tableArray("walls")) {
    const std::string type = t.requiredString("type", {"plane", "polygon", "mesh", "box"});
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
      if (w.vertices.size() < 3) t.fail("vertices", "a polygon needs at least 3 vertices [[x,y,z], ...]");
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
        const auto tris = t.vec3List("triangles");
        if (tris.empty()) t.fail("triangles", "a mesh wall needs `file` or `vertices` + `triangles`");
        for (const Vec3& tri : tris)
          w.mesh.triangles.push_back({static_cast<std::uint32_t>(tri[0]), static_cast<std::uint32_t>(tri[1]),
                                      static_cast<std::uint32_t>(tri[2])});
      }
      const std::string msg = w.mesh.validate();
      if (!msg.empty()) t.fail(t.has("file") ? "file" : "triangles", msg);
      model.walls.push_back(w);
    } else {  // box: five planes (open top) or six, facing inwards
      const Vec3 lo = t.requiredVec3("min"), hi = t.requiredVec3("max");
      if (!((hi - lo).minCoeff() > 0)) t.fail("max", "must exceed min in every component");
      const bool open_top = t.boolean("open_top", true);
      const std::pair<const char*, std::pair<Vec3, Vec3>> faces[] = {
          {"floor", {lo, Vec3::UnitZ()}},  {"xmin", {lo, Vec3::UnitX()}}, {"xmax", {hi, -Vec3::UnitX()}},
          {"ymin", {lo, Vec3::UnitY()}},   {"ymax", {hi, -Vec3::UnitY()}}, {"top", {hi, -Vec3::UnitZ()}}};
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
    t.finish();
  }
}

void readParticles(TableReader& root, const std::map<std::string, int>& materials, std::uint64_t seed,
                   std::vector<sim::SphereSpec>& spheres) {
  std::size_t source_index = 0;
  for (TableReader t : root.tableArray("particles")) {
    const std::string type = t.requiredString("type", {"lattice", "random", "list"});
    const int material = materialIndex(t, materials);
    const Vec3 velocity = t.vec3("velocity", Vec3::Zero());
    std::vector<Vec3> points;
    std::vector<double> radii;
    if (type == "lattice") {
      const double radius = t.requiredNumber("radius", Range::positive());
      const std::string kind = t.string("lattice", "sc", {"sc", "bcc", "fcc"});
      const double cell = t.requiredNumber("cell", Range::positive());
      const Vec3 offset = t.vec3("offset", Vec3::Zero());
      const Vec3 corner = t.vec3("corner", Vec3::Zero());
      const Vec3 counts = t.requiredVec3("counts");
      std::array<int, 3> n{};
      for (int k = 0; k < 3; ++k) {
        if (counts[k] < 1 || counts[k] != std::floor(counts[k]) || counts[k] > 1e4)
          t.fail("counts", "expected 3 whole numbers in [1, 10000]");
        n[k] = static_cast<int>(counts[k]);
      }
      const auto lk = kind == "sc" ? geometry::LatticeKind::SimpleCubic
                      : kind == "bcc" ? geometry::LatticeKind::BodyCentred
                                      : geometry::LatticeKind::FaceCentred;
      points = geometry::latticePoints(lk, cell, offset, corner, n);
      radii.assign(points.size(), radius);
    } else if (type == "random") {
      const auto count = t.integer("count", 0, Range::closed(1, 1e7));
      if (!t.has("count")) t.fail("count", "missing; the number of spheres to insert is required");
      double r_min, r_max;
      if (t.has("radius")) {
        r_min = r_max = t.number("radius", 0, Range::positive());
      } else {
        r_min = t.requiredNumber("radius_min", Range::positive());
        r_max = t.requiredNumber("radius_max", Range::positive());
        if (r_max < r_min) t.fail("radius_max", "must be >= radius_min");
      }
      const Vec3 lo = t.requiredVec3("region_min"), hi = t.requiredVec3("region_max");
      if (!((hi - lo).minCoeff() > 2 * r_max)) t.fail("region_max", "the region must be wider than a sphere");
      // Each source has its own stream, so adding a source does not move the others.
      geometry::Rng rng(seed * 1000003ull + source_index);
      for (std::int64_t k = 0; k < count; ++k) radii.push_back(rng.uniform(r_min, r_max));
      std::vector<geometry::Sphere> existing;
      for (const auto& s : spheres) existing.push_back({s.position, s.radius});
      points = geometry::randomNonOverlapping(radii, lo, hi, existing, rng);
      if (points.size() < radii.size())
        t.fail("count", "only " + std::to_string(points.size()) + " of " + std::to_string(radii.size()) +
                            " spheres fit in the region without overlap; enlarge region_min/region_max or lower count");
    } else {
      points = t.vec3List("positions");
      if (points.empty()) t.fail("positions", "a list needs positions = [[x, y, z], ...]");
      if (t.has("radii")) {
        radii = t.numberList("radii", Range::positive());
        if (radii.size() != points.size()) t.fail("radii", "needs one radius per position");
      } else {
        radii.assign(points.size(), t.requiredNumber("radius", Range::positive()));
      }
      const auto velocities = t.vec3List("velocities");
      if (!velocities.empty() && velocities.size() != points.size())
        t.fail("velocities", "needs one velocity per position");
      const auto omegas = t.vec3List("omegas");
      if (!omegas.empty() && omegas.size() != points.size()) t.fail("omegas", "needs one per position");
      for (std::size_t k = 0; k < points.size(); ++k) {
        sim::SphereSpec s;
        s.position = points[k];
        s.radius = radii[k];
        s.material = material;
        s.velocity = velocities.empty() ? velocity : velocities[k];
        s.omega = omegas.empty() ? Vec3::Zero() : omegas[k];
        spheres.push_back(s);
      }
      points.clear();
    }
    for (std::size_t k = 0; k < points.size(); ++k) {
      sim::SphereSpec s;
      s.position = points[k];
      s.radius = radii[k];
      s.material = material;
      s.velocity = velocity;
      spheres.push_back(s);
    }
    t.finish();
    ++source_index;
  }
}

Scene readScene(const toml::table& root_table, const std::filesystem::path& base_dir,
                std::shared_ptr<const TableReader::Overrides> overrides) {
  Scene scene;
  TableReader root(root_table, "", std::move(overrides));

  // [scene]
  {
    auto t = root.table("scene");
    if (!t) root.fail("scene", "missing; a [scene] table with name and end_time (or steps) is required");
    scene.run.name = t->requiredString("name");
    scene.run.description = t->string("description", "");
    scene.run.seed = static_cast<std::uint64_t>(t->integer("seed", 1, Range::nonNegative()));
    scene.run.end_time = t->number("end_time", 0.0, Range::nonNegative());
    scene.run.steps = static_cast<std::uint64_t>(t->integer("steps", 0, Range::nonNegative()));
    if ((scene.run.end_time > 0) == (scene.run.steps > 0))
      t->fail(t->has("steps") ? "steps" : "end_time", "give exactly one of end_time (s, > 0) and steps (> 0)");
    t->finish();
  }
  sim::Model& model = scene.model;

  // [materials.NAME]
  std::map<std::string, int> materials;
  {
    auto t = root.table("materials");
    if (!t) root.fail("materials", "missing; define at least one [materials.NAME] table");
    for (const std::string& name : t->keys()) {
      auto mt = t->table(name);
      materials[name] = static_cast<int>(model.materials.size());
      model.materials.push_back(readMaterial(*mt, name));
    }
    if (model.materials.empty()) root.fail("materials", "define at least one [materials.NAME] table");
    t->finish();
  }

  // [contact]
  if (auto t = root.table("contact")) {
    const std::string law = t->string("law", "linear", {"linear", "hertz_mindlin"});
    model.contact.law = law == "linear" ? sim::ContactLaw::Linear : sim::ContactLaw::HertzMindlin;
    model.contact.damping_normal = t->number("damping_normal", 0.0, {0.0, 1.0, false, true});
    model.contact.damping_shear = t->number("damping_shear", model.contact.damping_normal, {0.0, 1.0, false, true});
    const std::string mass = t->string("damping_mass", "average", {"average", "reduced"});
    model.contact.damping_mass = mass == "average" ? sim::DampingMass::Average : sim::DampingMass::Reduced;
    model.contact.local_damping = t->number("local_damping", 0.0, {0.0, 1.0, false, true});
    t->finish();
  }
  if (model.contact.law == sim::ContactLaw::HertzMindlin)
    for (const auto& m : model.materials)
      if (!(m.shear_modulus > 0))
        root.fail("materials", "material '" + m.name + "' needs shear_modulus > 0 Pa for contact.law = \"hertz_mindlin\"");

  // [gravity]
  if (auto t = root.table("gravity")) {
    model.gravity = t->vec3("vector", model.gravity);
    for (TableReader c : t->tableArray("change")) {
      sim::GravityChange g;
      g.time = c.requiredNumber("time", Range::nonNegative());
      g.vector = c.requiredVec3("vector");
      if (!model.gravity_changes.empty() && g.time <= model.gravity_changes.back().time)
        c.fail("time", "gravity changes must be in increasing time order");
      model.gravity_changes.push_back(g);
      c.finish();
    }
    t->finish();
  }

  // [timestep], [neighbours], [watchdog]
  if (auto t = root.table("timestep")) {
    model.timestep.safety_factor = t->number("safety_factor", model.timestep.safety_factor, {0.0, 1.0, true, false});
    model.timestep.dt = t->number("dt", 0.0, Range::nonNegative());
    model.timestep.impact_velocity = t->number("impact_velocity", model.timestep.impact_velocity, Range::positive());
    model.timestep.allow_unsafe = t->boolean("allow_unsafe", false);
    t->finish();
  }
  if (auto t = root.table("neighbours")) {
    model.skin = t->number("skin", 0.0, Range::nonNegative());
    model.max_grid_levels = static_cast<int>(t->integer("max_levels", model.max_grid_levels, Range::closed(1, 8)));
    t->finish();
  }
  if (auto t = root.table("watchdog")) {
    model.watchdog.max_overlap_fraction =
        t->number("max_overlap_fraction", model.watchdog.max_overlap_fraction, {0.0, 2.0, true, false});
    model.watchdog.max_energy_growth =
        t->number("max_energy_growth", model.watchdog.max_energy_growth, Range::nonNegative());
    model.watchdog.check_interval = static_cast<int>(
        t->integer("check_interval", model.watchdog.check_interval, Range::closed(1, 1e9)));
    t->finish();
  }

  readWalls(root, materials, base_dir, model);
  readParticles(root, materials, scene.run.seed, scene.spheres);

  // [output]
  if (auto t = root.table("output")) {
    RunSettings& r = scene.run;
    r.frame_interval = t->number("frame_interval", 0.0, Range::nonNegative());
    r.energy_interval = t->number("energy_interval", 0.0, Range::nonNegative());
    r.checkpoint_interval = t->number("checkpoint_interval", 0.0, Range::nonNegative());
    r.hdf5 = t->boolean("hdf5", r.hdf5);
    r.vtk = t->boolean("vtk", r.vtk);
    r.checkpoint = t->boolean("checkpoint", r.checkpoint);
    t->finish();
  }
  root.finish();
  return scene;
}

}  // namespace

Scene loadSceneText(const std::string& text, const std::string& source_name,
                    const std::vector<std::string>& overrides, const std::filesystem::path& base_dir) {
  toml::table table;
  try {
    table = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << source_name << ":" << e.source().begin.line << ": TOML syntax error: " << e.description();
    throw SceneError(s.str());
  }
  auto applied = std::make_shared<TableReader::Overrides>();
  for (const std::string& o : overrides) {
    detail::applyOverride(table, o);
    (*applied)[o.substr(0, o.find('='))] = o;
  }
  Scene scene = readScene(table, base_dir, applied);
  std::ostringstream effective;
  effective << table;
  scene.text = effective.str();
  return scene;
}

Scene loadScene(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in) throw SceneError(path.string() + ": cannot open the scene file (does it exist?)");
  std::stringstream buf;
  buf << in.rdbuf();
  Scene scene = loadSceneText(buf.str(), path.string(), overrides, path.parent_path());
  scene.source = path;
  return scene;
}

std::filesystem::path builtinSceneDir() { return std::filesystem::path(ROCKLAB_ASSET_DIR) / "scenes"; }

std::filesystem::path resolveScene(const std::string& name_or_path) {
  const std::filesystem::path p(name_or_path);
  if (std::filesystem::exists(p)) return p;
  if (p.extension().empty() && p.parent_path().empty()) {
    const auto builtin = builtinSceneDir() / (name_or_path + ".toml");
    if (std::filesystem::exists(builtin)) return builtin;
  }
  return p;  // loadScene reports it missing
}

}  // namespace rocklab::experiments
