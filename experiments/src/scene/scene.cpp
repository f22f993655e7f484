#include "rocklab/experiments/scene.h"

#include <cmath>
#include <algorithm>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "rocklab/geometry/clump_shape.h"
#include "rocklab/geometry/mesh_import.h"
#include "rocklab/geometry/packing.h"
#include "drivers/registry.h"
#include "scene/toml_reader.h"

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

/// An RGB colour [r, g, b] with channels in [0, 1].
render::Rgb readColour(TableReader& t, const std::string& key, render::Rgb fallback) {
  if (!t.has(key)) return fallback;
  const Vec3 c = t.vec3(key, Vec3::Zero());
  if (c.minCoeff() < 0 || c.maxCoeff() > 1) t.fail(key, "expected [r, g, b] with each channel in [0, 1]");
  return {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
}

/// How a wall is drawn: colour, opacity, visible, plane_size (keys of [[walls]]).
WallLook readWallLook(TableReader& t) {
  WallLook look;
  look.colour = readColour(t, "colour", look.colour);
  look.opacity = static_cast<float>(t.number("opacity", look.opacity, Range::closed(0, 1)));
  look.visible = t.boolean("visible", look.visible);
  look.plane_size = t.number("plane_size", look.plane_size, Range::positive());
  return look;
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
               const std::filesystem::path& base_dir, sim::Model& model, std::vector<WallLook>& looks) {
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
      if (w.vertices.size() < 3) t.fail("vertices", "a polygon needs at least 3 vertices [[x,y,z], ...]");
      model.walls.push_back(w);
    } else if (type == "plate") {
      // A rectangle from `corner`: `length` along x turned up by angle_deg about
      // y, `width` along y. The zoned chute's top plate: corner at the CSS above
      // the outlet, angle = bite angle (experiments.md §d).
      const Vec3 corner = t.requiredVec3("corner");
      const double length = t.requiredNumber("length", Range::positive());
      const double width = t.requiredNumber("width", Range::positive());
      const double angle = t.number("angle_deg", 0.0, Range::closed(-90, 90)) * std::numbers::pi / 180.0;
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
    looks.resize(model.walls.size(), look);  // a box adds several walls with one look
    t.finish();
  }
}

/// A body shape of one particle source: a sphere, or a clump with its members
/// in the principal frame centred on the centre of mass.
struct BodyShape {
  std::vector<geometry::Sphere> members;  // empty for a sphere
  double mass = 0;
  Vec3 inertia = Vec3::Zero();
};

/// Reads `shape` and its size keys; fills `report` for clumps.
BodyShape readClumpShape(TableReader& t, const std::string& shape, double density,
                         const std::filesystem::path& base_dir, ClumpShapeReport& report) {
  std::vector<geometry::Sphere> members;
  std::string default_volume = "union";
  if (shape == "four_ball") {
    if (t.has("member_radius") == t.has("equivalent_diameter"))
      t.fail("member_radius", "give exactly one of member_radius (m) and equivalent_diameter (m, Eq 4-2 sizing)");
    const double r = t.has("member_radius") ? t.number("member_radius", 0, Range::positive())
                                            : geometry::fourBallRadiusForEquivalentDiameter(
                                                  t.number("equivalent_diameter", 0, Range::positive()));
    members = geometry::fourBallClump(r);
    default_volume = "eq42";  // the study sized its clumps with Eq 4-2
    report.shape = "four_ball";
  } else {
    const std::filesystem::path file = base_dir / t.requiredString("file");
    const double scale = t.number("scale", 1.0, Range::positive());
    try {
      members = geometry::readClumpFile(file.string());
    } catch (const std::exception& e) {
      t.fail("file", e.what());
    }
    for (auto& m : members) {
      m.centre *= scale;
      m.radius *= scale;
    }
    report.shape = file.string();
  }
  const std::string distribution = t.string("mass_distribution", "union", {"union", "equal_mass", "sum"});
  const auto dist = distribution == "union"        ? geometry::ClumpMassDistribution::Union
                    : distribution == "equal_mass" ? geometry::ClumpMassDistribution::EqualMass
                                                   : geometry::ClumpMassDistribution::Sum;
  double total_mass = t.number("mass", 0.0, Range::nonNegative());
  const std::string volume = t.string("mass_volume", default_volume, {"eq42", "union", "sum"});
  if (total_mass > 0 && t.has("mass_volume")) t.fail("mass", "give mass (kg) or mass_volume, not both");
  if (volume == "eq42" && shape != "four_ball") t.fail("mass_volume", "\"eq42\" applies to the four-ball clump only");
  auto props = geometry::clumpMassProperties(members, density, dist);
  if (total_mass == 0) {
    double v = props.union_volume;
    if (volume == "eq42") v = geometry::fourBallVolumeEq42(members.front().radius);
    if (volume == "sum") {
      v = 0;
      for (const auto& m : members) v += 4.0 / 3.0 * std::numbers::pi * std::pow(m.radius, 3);
    }
    total_mass = density * v;
  }
  props = geometry::clumpMassProperties(members, density, dist, total_mass);
  BodyShape body;
  body.mass = props.mass;
  body.inertia = props.principal_moments;
  // A clump made from a mesh (`rocklab shape`) carries the mesh's own mass properties:
  // the spheres set the contact surface, the solid they stand for sets the inertia. Its
  // file is written in the mesh's principal frame, so with principal_inertia the file's
  // origin is the centre of mass and its x, y, z axes are the principal axes of these
  // moments: the members are kept as they are (the union's own axes would differ, e.g.
  // by 26 deg in the plane of a flake whose two larger moments are close).
  if (t.has("principal_inertia")) {
    if (!t.has("mass")) t.fail("principal_inertia", "give mass (kg) with principal_inertia (both are in rocklab shape's clump.toml)");
    const Vec3 moments = t.requiredVec3("principal_inertia");
    for (int a = 0; a < 3; ++a)
      if (!(moments[a] > 0) || moments[a] > (moments.sum() - moments[a]) * (1 + 1e-9))
        t.fail("principal_inertia", "expected three positive moments (kg m^2) about the clump file's x, y, z axes, "
                                    "each at most the sum of the other two");
    body.inertia = moments;
    body.members = members;
  } else {
    for (const auto& m : members)
      body.members.push_back({props.principal_axes.transpose() * (m.centre - props.centre_of_mass), m.radius});
  }
  report.members = members.size();
  report.mass = props.mass;
  report.volume = props.mass / density;
  report.union_volume = props.union_volume;
  report.union_volume_error = props.union_volume_error;
  report.equivalent_diameter = std::cbrt(6.0 * report.volume / std::numbers::pi);
  report.distribution = distribution;
  report.principal_inertia = body.inertia;
  return body;
}

void readParticles(TableReader& root, const std::map<std::string, int>& materials,
                   const std::vector<sim::Material>& material_list, std::uint64_t seed,
                   const std::filesystem::path& base_dir, Scene& scene) {
  std::vector<sim::SphereSpec>& spheres = scene.spheres;
  std::size_t source_index = 0;
  // Every ball placed so far (clump members in world position), for insertion.
  std::vector<geometry::Sphere> placed;
  for (TableReader t : root.tableArray("particles")) {
    const std::string type = t.requiredString("type", {"lattice", "random", "list"});
    const int material = materialIndex(t, materials);
    const Vec3 velocity = t.vec3("velocity", Vec3::Zero());
    const std::string shape = t.string("shape", "sphere", {"sphere", "four_ball", "file"});
    // Each source has its own stream, so adding a source does not move the others.
    geometry::Rng rng(seed * 1000003ull + source_index);
    BodyShape body;
    if (shape != "sphere") {
      ClumpShapeReport report;
      report.source = t.path();
      body = readClumpShape(t, shape, material_list[static_cast<std::size_t>(material)].density, base_dir, report);
      scene.clump_shapes.push_back(report);
    }
    const bool clumps = !body.members.empty();
    std::vector<Vec3> points;
    std::vector<double> radii;
    std::vector<geometry::Quat> orientations;
    if (type == "lattice") {
      const double radius = clumps ? 0.0 : t.requiredNumber("radius", Range::positive());
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
      const Vec3 lo = t.requiredVec3("region_min"), hi = t.requiredVec3("region_max");
      double r_min = 0, r_max = 0, body_volume = 0;
      if (clumps) {
        body_volume = scene.clump_shapes.back().union_volume;
      } else {
        if (t.has("radius")) {
          r_min = r_max = t.number("radius", 0, Range::positive());
        } else {
          r_min = t.requiredNumber("radius_min", Range::positive());
          r_max = t.requiredNumber("radius_max", Range::positive());
          if (r_max < r_min) t.fail("radius_max", "must be >= radius_min");
        }
        if (!((hi - lo).minCoeff() > 2 * r_max)) t.fail("region_max", "the region must be wider than a sphere");
        // Mean volume of radii uniform in [r_min, r_max]: (4/3) pi <r^3>.
        const double mean_r3 = r_max > r_min ? (std::pow(r_max, 4) - std::pow(r_min, 4)) / (4 * (r_max - r_min))
                                             : std::pow(r_min, 3);
        body_volume = 4.0 / 3.0 * std::numbers::pi * mean_r3;
      }
      if (t.has("count") == t.has("solid_fraction"))
        t.fail("count", "give exactly one of count (particles) and solid_fraction (of the region volume, "
                        "so that a size sweep fills the same space)");
      std::int64_t count = t.integer("count", 0, Range::closed(1, 1e7));
      if (t.has("solid_fraction")) {
        const double f = t.number("solid_fraction", 0, {0.0, 0.6, true, false});
        const double region = (hi - lo).cwiseMax(Vec3::Zero()).prod();
        count = static_cast<std::int64_t>(std::floor(f * region / body_volume));
        if (count < 1) t.fail("solid_fraction", "gives no particle in this region");
      }
      if (clumps) {
        const std::vector<const std::vector<geometry::Sphere>*> shapes(static_cast<std::size_t>(count), &body.members);
        const auto poses = geometry::randomNonOverlappingBodies(shapes, lo, hi, placed, rng);
        if (poses.size() < shapes.size())
          t.fail(t.has("count") ? "count" : "solid_fraction", "only " + std::to_string(poses.size()) + " of " + std::to_string(shapes.size()) +
                              " clumps fit in the region without overlap; enlarge region_min/region_max or ask for fewer");
        for (const auto& pose : poses) {
          points.push_back(pose.position);
          orientations.push_back(pose.orientation);
        }
      } else {
        for (std::int64_t k = 0; k < count; ++k) radii.push_back(rng.uniform(r_min, r_max));
        points = geometry::randomNonOverlapping(radii, lo, hi, placed, rng);
        if (points.size() < radii.size())
          t.fail(t.has("count") ? "count" : "solid_fraction", "only " + std::to_string(points.size()) + " of " + std::to_string(radii.size()) +
                              " spheres fit in the region without overlap; enlarge region_min/region_max or ask for fewer");
      }
    } else {
      points = t.vec3List("positions");
      if (points.empty()) t.fail("positions", "a list needs positions = [[x, y, z], ...]");
      if (clumps) {
        radii.assign(points.size(), 0.0);
      } else if (t.has("radii")) {
        radii = t.numberList("radii", Range::positive());
        if (radii.size() != points.size()) t.fail("radii", "needs one radius per position");
      } else {
        radii.assign(points.size(), t.requiredNumber("radius", Range::positive()));
      }
    }
    std::vector<Vec3> velocities, omegas;
    if (type == "list") {
      velocities = t.vec3List("velocities");
      if (!velocities.empty() && velocities.size() != points.size())
        t.fail("velocities", "needs one velocity per position");
      omegas = t.vec3List("omegas");
      if (!omegas.empty() && omegas.size() != points.size()) t.fail("omegas", "needs one per position");
    }
    // Clumps not placed by the random insertion get random orientations too.
    if (clumps && t.boolean("random_orientation", true))
      while (orientations.size() < points.size()) orientations.push_back(geometry::randomRotation(rng));
    while (orientations.size() < points.size()) orientations.push_back(geometry::Quat::Identity());
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Vec3 v = velocities.empty() ? velocity : velocities[k];
      const Vec3 w = omegas.empty() ? Vec3::Zero() : omegas[k];
      if (clumps) {
        sim::ClumpSpec c;
        c.position = points[k];
        c.orientation = orientations[k];
        c.velocity = v;
        c.omega = w;
        c.mass = body.mass;
        c.principal_inertia = body.inertia;
        c.members = body.members;
        c.material = material;
        for (const auto& m : body.members) placed.push_back({points[k] + orientations[k] * m.centre, m.radius});
        scene.clumps.push_back(std::move(c));
      } else {
        sim::SphereSpec s;
        s.position = points[k];
        s.radius = radii[k];
        s.material = material;
        s.velocity = v;
        s.omega = w;
        placed.push_back({s.position, s.radius});
        spheres.push_back(s);
      }
    }
    t.finish();
    ++source_index;
  }
}

/// [[cameras]]: intrinsics (fov_deg, or fx/fy/cx/cy), pose (eye, target, up),
/// timing and outputs. Every camera field is checked by geometry::Camera::validate.
void readCameras(TableReader& root, std::vector<CameraSettings>& cameras) {
  for (TableReader t : root.tableArray("cameras")) {
    CameraSettings c;
    c.name = t.string("name", "camera" + std::to_string(cameras.size()));
    for (const auto& other : cameras)
      if (other.name == c.name) t.fail("name", "another camera has this name");
    std::vector<double> res = t.numberList("resolution", Range::closed(16, 8192));
    if (res.empty()) res = {640, 480};
    if (res.size() != 2 || res[0] != std::floor(res[0]) || res[1] != std::floor(res[1]))
      t.fail("resolution", "expected [width, height] in whole pixels, 16..8192");
    const int w = static_cast<int>(res[0]), h = static_cast<int>(res[1]);
    geometry::Camera& cam = c.camera;
    if (t.has("fov_deg")) {
      if (t.has("fx")) t.fail("fx", "give fov_deg or fx/fy/cx/cy, not both");
      cam = geometry::Camera::withFieldOfView(w, h, t.number("fov_deg", 60, {0.0, 179.0, true, false}));
    } else {
      cam.width = w;
      cam.height = h;
      cam.fx = t.requiredNumber("fx", Range::positive());
      cam.fy = t.number("fy", cam.fx, Range::positive());
      cam.cx = t.number("cx", 0.5 * (w - 1));
      cam.cy = t.number("cy", 0.5 * (h - 1));
    }
    cam.k1 = t.number("k1", 0.0);
    cam.k2 = t.number("k2", 0.0);
    cam.frameRate = t.number("frame_rate", 500.0, Range::positive());
    cam.exposureTime = t.number("exposure", 0.0, Range::nonNegative());
    const Vec3 eye = t.requiredVec3("eye"), target = t.requiredVec3("target");
    try {
      cam.lookAt(eye, target, t.vec3("up", Vec3::UnitZ()));
    } catch (const std::invalid_argument& e) {
      t.fail("up", e.what());
    }
    try {
      cam.validate();
    } catch (const std::invalid_argument& e) {
      t.fail("exposure", e.what());
    }
    c.start_time = t.number("start_time", c.start_time, Range::nonNegative());
    c.end_time = t.number("end_time", c.end_time, Range::positive());
    c.movie = t.boolean("movie", c.movie);
    c.movie_fps = t.number("movie_fps", c.movie_fps, Range::closed(1, 1000));
    c.still_interval = t.number("still_interval", c.still_interval, Range::nonNegative());
    c.all_frames = t.boolean("all_frames", c.all_frames);
    c.timestamp = t.boolean("timestamp", c.timestamp);
    c.scale_bar = t.boolean("scale_bar", c.scale_bar);
    c.scale_depth = t.number("scale_depth", (target - eye).norm(), Range::positive());
    c.motion_blur = t.boolean("motion_blur", c.motion_blur);
    c.noise_sigma = t.number("noise_sigma", c.noise_sigma, Range::closed(0, 100));
    c.light_gain = t.number("light_gain", c.light_gain, Range::closed(0, 10));
    if (c.motion_blur && !(cam.exposureTime > 0)) t.fail("motion_blur", "needs exposure > 0 s");
    t.finish();
    cameras.push_back(c);
  }
}

/// The [experiment] table: its type, and its keys read and checked by that
/// type's driver; nothing for a plain run.
void readExperiment(TableReader& root, Scene& scene) {
  auto t = root.table("experiment");
  if (!t) return;
  std::vector<std::string> types;
  for (const ExperimentDriver& d : experimentDrivers()) types.push_back(d.type);
  scene.experiment_type = t->requiredString("type", types);
  const double check_interval = t->number("check_interval", ExperimentSettings{}.check_interval, Range::positive());
  // The driver reads and checks the keys of its type into its settings (drivers/registry.cpp).
  auto settings = findExperimentDriver(scene.experiment_type)->read_settings(*t, SettingsContext{scene.model, scene.cameras});
  settings->check_interval = check_interval;
  t->finish();
  scene.experiment = std::move(settings);
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
      scene.material_colours.push_back(readColour(*mt, "colour", render::kGreyPebble));
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
    // Stiffness scaling, the usual way DEM users buy speed (dt_crit ~ 1/sqrt(k)):
    // one factor on every material's kn, ks and G, so a study varies one key.
    const double scale = t->number("stiffness_scale", 1.0, Range::positive());
    for (auto& m : model.materials) {
      m.kn *= scale;
      m.ks *= scale;
      m.shear_modulus *= scale;
    }
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
    model.watchdog.network_iterations = static_cast<int>(
        t->integer("network_iterations", model.watchdog.network_iterations, Range::closed(0, 1000)));
    model.watchdog.network_interval = static_cast<int>(
        t->integer("network_interval", model.watchdog.network_interval, Range::closed(1, 1e9)));
    t->finish();
  }
  if (auto t = root.table("relaxation")) {
    model.relaxation.steps = static_cast<int>(t->integer("steps", 0, Range::closed(0, 1e9)));
    t->finish();
  }

  readWalls(root, materials, base_dir, model, scene.wall_looks);
  readParticles(root, materials, model.materials, scene.run.seed, base_dir, scene);

  readCameras(root, scene.cameras);
  readExperiment(root, scene);

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

namespace {

toml::table parseToml(const std::string& text, const std::string& source_name) {
  try {
    return toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << source_name << ":" << e.source().begin.line << ": TOML syntax error: " << e.description();
    throw SceneError(s.str());
  }
}

/// Lays `over` onto `base`: tables merge key by key, anything else (numbers,
/// strings, arrays, arrays of tables such as [[walls]]) replaces the base value.
void mergeInto(toml::table& base, const toml::table& over) {
  for (const auto& [key, value] : over) {
    toml::table* base_table = base[key].as_table();
    if (base_table && value.is_table())
      mergeInto(*base_table, *value.as_table());
    else
      base.insert_or_assign(key, value);
  }
}

/// A scene may start with `extends = "other.toml"` (path relative to the scene):
/// it then holds only what differs from that scene, e.g. another inclination.
void resolveExtends(toml::table& table, const std::string& source_name, const std::filesystem::path& base_dir,
                    int depth) {
  const toml::node* e = table.get("extends");
  if (!e) return;
  const auto name = e->value<std::string>();
  if (!name) throw SceneError(source_name + ": extends: expected the file name of the scene to extend");
  if (depth > 8) throw SceneError(source_name + ": extends: more than 8 levels (a cycle?)");
  const std::filesystem::path file = base_dir / *name;
  std::ifstream in(file);
  if (!in) throw SceneError(source_name + ": extends = \"" + *name + "\": cannot open " + file.string());
  std::stringstream buf;
  buf << in.rdbuf();
  toml::table base = parseToml(buf.str(), file.string());
  resolveExtends(base, file.string(), file.parent_path(), depth + 1);
  table.erase("extends");
  mergeInto(base, table);
  table = std::move(base);
}

}  // namespace

Scene loadSceneText(const std::string& text, const std::string& source_name,
                    const std::vector<std::string>& overrides, const std::filesystem::path& base_dir) {
  toml::table table = parseToml(text, source_name);
  resolveExtends(table, source_name, base_dir, 0);
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

std::vector<CameraSettings> loadCameras(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw SceneError(path.string() + ": cannot open the camera file (does it exist?)");
  std::stringstream buf;
  buf << in.rdbuf();
  const toml::table table = parseToml(buf.str(), path.string());
  TableReader root(table, "");
  std::vector<CameraSettings> cameras;
  readCameras(root, cameras);
  root.finish();
  if (cameras.empty()) throw SceneError(path.string() + ": no [[cameras]] table");
  return cameras;
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
