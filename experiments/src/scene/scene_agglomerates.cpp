// Scene reader: [[particles]] of type "agglomerate", bonded spheres placed as
// one body (experiments.md §f): the hexagonal close packing of the anisotropy
// study (§f.3), every touching pair bonded, or one agglomerate of a library
// written by `rocklab agglomerate` (dense random packing §f.4, carved from a
// scan §f.7, or HCP), with its bonds, or a dense random packing made here
// (§f.4: the same generator as `rocklab agglomerate --method dense`).
#include <cmath>
#include <iomanip>
#include <map>
#include <mutex>
#include <numbers>
#include <sstream>

#include "agglomerate/agglomerate_library.h"
#include "agglomerate/agglomerate_methods.h"
#include "rocklab/geometry/bond_pairs.h"
#include "rocklab/geometry/clump_shape.h"
#include "rocklab/geometry/hcp_packing.h"
#include "rocklab/geometry/structure_statistics.h"
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

/// Rotation by angles (deg) about x, then y, then z (world axes).
geometry::Quat rotationFromDegrees(const Vec3& deg) {
  const double k = std::numbers::pi / 180.0;
  return geometry::Quat(Eigen::AngleAxisd(deg.z() * k, Vec3::UnitZ()) *
                        Eigen::AngleAxisd(deg.y() * k, Vec3::UnitY()) *
                        Eigen::AngleAxisd(deg.x() * k, Vec3::UnitX()));
}

}  // namespace

namespace {

/// An agglomerate in its own frame: spheres, bonded pairs and what describes it.
struct Body {
  std::vector<geometry::Sphere> spheres;
  std::vector<geometry::SpherePair> pairs;
  double diameter = 0, porosity = 0, coordination_number = 0;
};

/// The HCP packing of `radius` spheres in a sphere of `diameter` (§f.3), every
/// touching pair bonded; errors name `diameter_key`.
Body makeHcp(TableReader& t, double radius, double diameter, double angle, double gap_tolerance,
             const std::string& diameter_key) {
  // Counted before the packing is made (a 100 m sphere of 2.5 mm balls hung in it):
  // HCP fills 0.7405 of the sphere.
  const double expected = 0.7405 * std::pow(diameter / (2 * radius), 3);
  if (expected > 2e6) {
    std::ostringstream what;
    what << std::setprecision(3) << "gives about " << expected << " spheres of radius " << radius
         << " m; an agglomerate may have at most 2e6";
    t.fail(diameter_key, what.str());
  }
  Body body;
  try {
    body.spheres = geometry::hcpPacking(radius, diameter, angle);
  } catch (const std::invalid_argument& e) {
    t.fail("radius", e.what());
  }
  if (body.spheres.size() > 2000000) t.fail(diameter_key, "gives more than 2e6 spheres");
  body.pairs = geometry::bondPairs(body.spheres, gap_tolerance);
  const geometry::StructureStatistics stats = geometry::structureStatistics(
      body.spheres, std::numbers::pi / 6.0 * diameter * diameter * diameter, gap_tolerance);
  body.diameter = diameter;
  body.porosity = stats.porosity;
  body.coordination_number = stats.coordination_number;
  return body;
}

/// An HCP source (agglomerate frame).
Body readHcp(TableReader& t) {
  const double radius = t.requiredNumber("radius", Range::positive());
  const double diameter = t.requiredNumber("diameter", Range::positive());
  if (diameter < 2 * radius) t.fail("diameter", "must be at least two sphere radii");
  // Layers stacked along y, turned by hcp_angle about z (§f.3): the angle
  // between the stacking axis and y, which the platens of a test along y see.
  const double angle = t.number("hcp_angle", 0.0, Range::closed(0, 90));
  const double gap_tolerance = t.number("gap_tolerance", 1e-3, Range::closed(0, 0.5));
  return makeHcp(t, radius, diameter, angle, gap_tolerance, "diameter");
}

/// Agglomerate `index` of a library file (its own bonds); `method` becomes
/// "library:<its method>".
Body readLibrary(TableReader& t, const std::filesystem::path& base_dir, std::string& method) {
  const std::filesystem::path file = base_dir / t.requiredString("library");
  std::vector<AgglomerateRecord> library;
  try {
    library = readAgglomerateLibrary(file);
  } catch (const std::exception& e) {
    t.fail("library", e.what());
  }
  const std::int64_t index = t.integer("index", 0, Range::closed(0, 1e9));
  if (static_cast<std::size_t>(index) >= library.size())
    t.fail("index", "the library " + file.string() + " holds " + std::to_string(library.size()) +
                        " agglomerates (indices 0.." + std::to_string(library.size() - 1) + ")");
  const AgglomerateRecord& a = library[static_cast<std::size_t>(index)];
  Body body;
  body.spheres = a.spheres;
  for (const auto& b : a.bonds) body.pairs.emplace_back(b[0], b[1]);
  body.diameter = a.diameter;
  body.porosity = a.porosity;
  body.coordination_number = a.coordination_number;
  method = "library:" + a.method;
  return body;
}

/// A dense random packing (§f.4) of `spec`, made once per process: a sweep or study
/// loads the scene once per variant to check it before any run, and the same spec
/// gives the same agglomerate. Errors name `diameter_key`.
Body makeDense(TableReader& t, const agglomerate::AgglomerateSpec& spec, const std::string& diameter_key) {
  static std::mutex memo_mutex;
  static std::map<std::string, agglomerate::GeneratedAgglomerate> memo;
  std::ostringstream key;
  key << std::hexfloat << spec.r_max << ' ' << spec.diameter << ' ' << spec.r0 << ' ' << spec.gap_tolerance
      << ' ' << spec.seed << ' ' << static_cast<int>(spec.pack.kind);
  agglomerate::GeneratedAgglomerate made;
  {
    std::lock_guard<std::mutex> lock(memo_mutex);
    auto it = memo.find(key.str());
    if (it == memo.end()) {
      try {
        it = memo.emplace(key.str(), agglomerate::generateAgglomerate(spec)).first;
      } catch (const std::exception& e) {
        t.fail(diameter_key, std::string("no dense agglomerate: ") + e.what());
      }
    }
    made = it->second;
  }
  Body body;
  body.spheres = std::move(made.spheres);
  body.pairs = std::move(made.bonds);
  body.diameter = made.diameter;
  body.porosity = made.structure.porosity;
  body.coordination_number = made.structure.coordination_number;
  return body;
}

/// The dense random packing's settings (§f.4) but the diameter and r_max; errors
/// about the sphere count name `diameter_key`.
agglomerate::AgglomerateSpec denseSpec(TableReader& t, double r_max, double diameter, const std::string& diameter_key) {
  agglomerate::AgglomerateSpec spec;
  spec.method = agglomerate::Method::Dense;
  spec.r_max = r_max;
  spec.diameter = diameter;
  if (spec.diameter < 4 * spec.r_max) t.fail(diameter_key, "must be at least four sphere radii (radius = r_max)");
  spec.r0 = t.number("r0", 4.0, Range::closed(1, 20));
  spec.gap_tolerance = t.number("gap_tolerance", 1e-3, Range::closed(0, 0.5));
  spec.seed = static_cast<std::uint64_t>(t.integer("seed", 1, Range::closed(0, 1e15)));
  spec.pack.kind = agglomerate::parsePackKind(t.string("pack", "servo", {"servo", "geometric"}));
  const double solid = std::pow(spec.diameter / spec.r_max, 3) / 8.0;  // r_max spheres in the diameter
  if (solid * std::pow(spec.r0, 3) > 4e6)
    t.fail("r0", "gives more than about 2e6 spheres for this diameter and radius");
  return spec;
}

/// A dense random packing (§f.4) made at load time: the servo-compacted loose pack
/// of r_max spheres filling the diameter, its voids filled down to r_max / r0.
/// Its own seed (not the scene's), so a study can turn one agglomerate through
/// random orientations (scene.seed) or draw new ones (seed).
Body readDense(TableReader& t) {
  const double r_max = t.requiredNumber("radius", Range::positive());
  const double diameter = t.requiredNumber("diameter", Range::positive());
  return makeDense(t, denseSpec(t, r_max, diameter, "diameter"), "diameter");
}

/// Appends `body` turned by q, scaled by `scale` and centred at `centre` as spheres
/// and bonds of the scene, with its report.
void place(const Body& body, const geometry::Quat& q, double scale, const Vec3& centre, const Vec3& velocity,
           int material, AgglomerateReport report, Scene& scene) {
  report.first_ball = scene.spheres.size();
  report.balls = body.spheres.size();
  report.first_bond = scene.bonds.size();
  report.bonds = body.pairs.size();
  report.diameter = scale * body.diameter;
  report.porosity = body.porosity;
  report.coordination_number = body.coordination_number;
  for (const geometry::Sphere& s : body.spheres) {
    sim::SphereSpec spec;
    spec.position = centre + q * (scale * s.centre);
    spec.radius = scale * s.radius;
    spec.velocity = velocity;
    spec.material = material;
    scene.spheres.push_back(spec);
    report.solid_volume += 4.0 / 3.0 * std::numbers::pi * std::pow(spec.radius, 3);
  }
  for (const auto& [a, b] : body.pairs) {
    sim::BondSpec bond;
    bond.a = static_cast<std::uint32_t>(report.first_ball + a);
    bond.b = static_cast<std::uint32_t>(report.first_ball + b);
    scene.bonds.push_back(bond);
  }
  scene.agglomerates.push_back(std::move(report));
}

}  // namespace

void readAgglomerate(TableReader& t, int material, const std::filesystem::path& base_dir,
                     geometry::Rng& rng, Scene& scene) {
  AgglomerateReport report;
  report.source = t.path();
  report.method = t.string("method", "hcp", {"hcp", "dense", "library"});
  const Body body = report.method == "hcp"     ? readHcp(t)
                    : report.method == "dense" ? readDense(t)
                                               : readLibrary(t, base_dir, report.method);
  // The agglomerate's frame -> world: a fixed rotation (deg about x, y, z),
  // followed by a random one (seeded) when orientation = "random", then the centre.
  geometry::Quat q = rotationFromDegrees(t.vec3("rotation", Vec3::Zero()));
  if (t.string("orientation", "given", {"given", "random"}) == "random")
    q = geometry::randomRotation(rng) * q;
  const Vec3 centre = t.requiredVec3("position");
  const Vec3 velocity = t.vec3("velocity", Vec3::Zero());
  place(body, q, 1.0, centre, velocity, material, std::move(report), scene);
}

void readAgglomerateFeed(TableReader& t, int material, geometry::Rng& rng, std::vector<geometry::Sphere>& placed,
                         Scene& scene) {
  if (!t.has("count")) t.fail("count", "is required: how many agglomerates to place");
  const auto count = static_cast<std::size_t>(t.integer("count", 1, Range::closed(1, 100000)));
  const double d_min = t.requiredNumber("diameter_min", Range::positive());
  const double d_max = t.requiredNumber("diameter_max", Range::positive());
  if (d_max < d_min) t.fail("diameter_max", "must be at least diameter_min");
  const auto templates = static_cast<std::size_t>(t.integer("templates", 3, Range::closed(1, 100)));
  const std::string method = t.string("method", "dense", {"hcp", "dense"});
  // r_max at diameter_max; every agglomerate has the same structure, scaled to its size.
  const double radius = t.requiredNumber("radius", Range::positive());
  const double angle = method == "hcp" ? t.number("hcp_angle", 0.0, Range::closed(0, 90)) : 0.0;
  const double gap_tolerance = method == "hcp" ? t.number("gap_tolerance", 1e-3, Range::closed(0, 0.5)) : 0.0;
  const Vec3 lo = t.requiredVec3("region_min"), hi = t.requiredVec3("region_max");
  const Vec3 velocity = t.vec3("velocity", Vec3::Zero());
  // Class k of `templates` equal widths of diameter has one agglomerate made at its
  // middle diameter; each feed particle is its class's, scaled to its own diameter
  // (uniform in [diameter_min, diameter_max]) and turned at random.
  std::vector<Body> bodies;
  const double width = (d_max - d_min) / static_cast<double>(templates);
  for (std::size_t k = 0; k < templates; ++k) {
    const double d = d_min + (static_cast<double>(k) + 0.5) * width;
    const double r = radius * d / d_max;
    if (method == "hcp")
      bodies.push_back(makeHcp(t, r, d, angle, gap_tolerance, "diameter_min"));
    else
      bodies.push_back(makeDense(t, denseSpec(t, r, d, "diameter_min"), "diameter_min"));
  }
  std::vector<double> diameters(count), radii(count);
  for (std::size_t i = 0; i < count; ++i) {
    diameters[i] = rng.uniform(d_min, d_max);
    radii[i] = 0.5 * diameters[i];
  }
  const std::vector<Vec3> centres = geometry::randomNonOverlapping(radii, lo, hi, placed, rng);
  if (centres.size() < count)
    t.fail("count", "only " + std::to_string(centres.size()) + " of " + std::to_string(count) +
                        " agglomerates fit in region_min..region_max without overlap (a larger region or fewer)");
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t k = std::min(templates - 1, static_cast<std::size_t>((diameters[i] - d_min) / std::max(width, 1e-300)));
    const Body& body = bodies[k];
    AgglomerateReport report;
    report.source = t.path();
    report.method = method;
    place(body, geometry::randomRotation(rng), diameters[i] / body.diameter, centres[i], velocity, material,
          std::move(report), scene);
    placed.push_back({centres[i], radii[i]});
  }
}

}  // namespace rocklab::experiments::detail
