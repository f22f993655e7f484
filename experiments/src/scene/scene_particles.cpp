// Scene reader: [[particles]] sources (lattice, random, list) of spheres or
// clumps (four_ball, clump files) with their mass properties.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "rocklab/geometry/clump_shape.h"
#include "rocklab/geometry/packing.h"
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

// The most balls (clump members counted) a scene may make, as `count` allows, and
// what one ball costs in memory: the World's per-ball state and contact history,
// the neighbour grid and pair lists, the scene's own copy. Measured 0.98 kB a ball
// (results.json peak_rss_bytes of touching simple-cubic lattices of 8,000 and
// 216,000 balls, 3 pairs a ball); 1.5 kB leaves room for denser packs and outputs.
constexpr double kMaxBalls = 1e7;
constexpr double kBytesPerBall = 1500;
// Random insertion (no overlap; each body tried 1000 times; it stops at the first
// body that does not fit) fills about 0.27 of a box with equal spheres (measured at
// 20 and 40 radii across: 0.275, 0.271), less with a size range (0.22 at r_max/r_min
// = 2) or clumps. Denser packs come from a lattice or from letting a deposit settle.
constexpr double kRandomInsertionReach = 0.3;

std::string memoryText(double balls) {
  const double gb = balls * kBytesPerBall / 1e9;
  std::ostringstream s;
  s << std::setprecision(2) << gb << " GB";
  return s.str();
}

/// Refuses a source that would take the scene past kMaxBalls before anything is
/// allocated for it, with the count and the memory it would take.
void checkBallBudget(const TableReader& t, const std::string& key, double bodies, double balls_per_body,
                     std::size_t balls_before) {
  const double balls = bodies * balls_per_body;
  if (balls + static_cast<double>(balls_before) <= kMaxBalls) return;
  std::ostringstream what;
  what << std::setprecision(3) << "asks for " << bodies << (balls_per_body > 1 ? " clumps" : " balls");
  if (balls_per_body > 1) what << " of " << balls_per_body << " balls";
  if (balls_before) what << " after " << balls_before << " balls of the sources before it";
  what << ": about " << memoryText(balls + static_cast<double>(balls_before)) << " of memory at ~"
       << kBytesPerBall / 1e3 << " kB a ball; a scene may hold at most " << kMaxBalls << " balls (about "
       << memoryText(kMaxBalls) << ")";
  t.fail(key, what.str());
}

/// Balls of the scene so far, clump members included.
std::size_t ballsSoFar(const Scene& scene) {
  std::size_t n = scene.spheres.size();
  for (const sim::ClumpSpec& c : scene.clumps) n += c.members.size();
  return n;
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
      t.fail("member_radius",
             "give exactly one of member_radius (m) and "
             "equivalent_diameter (m, Eq 4-2 sizing)");
    const double r = t.has("member_radius")
                         ? t.number("member_radius", 0, Range::positive())
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
  const std::string distribution =
      t.string("mass_distribution", "union", {"union", "equal_mass", "sum"});
  const auto dist = distribution == "union"        ? geometry::ClumpMassDistribution::Union
                    : distribution == "equal_mass" ? geometry::ClumpMassDistribution::EqualMass
                                                   : geometry::ClumpMassDistribution::Sum;
  double total_mass = t.number("mass", 0.0, Range::nonNegative());
  const std::string volume = t.string("mass_volume", default_volume, {"eq42", "union", "sum"});
  if (total_mass > 0 && t.has("mass_volume"))
    t.fail("mass", "give mass (kg) or mass_volume, not both");
  if (volume == "eq42" && shape != "four_ball")
    t.fail("mass_volume", "\"eq42\" applies to the four-ball clump only");
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
  // A clump made from a mesh (`rocklab shape`) carries the mesh's own mass
  // properties: the spheres set the contact surface, the solid they stand for
  // sets the inertia. Its file is written in the mesh's principal frame, so
  // with principal_inertia the file's origin is the centre of mass and its x,
  // y, z axes are the principal axes of these moments: the members are kept as
  // they are (the union's own axes would differ, e.g. by 26 deg in the plane of
  // a flake whose two larger moments are close).
  if (t.has("principal_inertia")) {
    if (!t.has("mass"))
      t.fail("principal_inertia",
             "give mass (kg) with principal_inertia (both "
             "are in rocklab shape's clump.toml)");
    const Vec3 moments = t.requiredVec3("principal_inertia");
    for (int a = 0; a < 3; ++a)
      if (!(moments[a] > 0) || moments[a] > (moments.sum() - moments[a]) * (1 + 1e-9))
        t.fail("principal_inertia",
               "expected three positive moments (kg m^2) "
               "about the clump file's x, y, z axes, "
               "each at most the sum of the other two");
    body.inertia = moments;
    body.members = members;
  } else {
    for (const auto& m : members)
      body.members.push_back(
          {props.principal_axes.transpose() * (m.centre - props.centre_of_mass), m.radius});
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

// The `diameters_file` of a random source: a CSV whose header names a diameter_mm
// (or diameter_m) column, one sphere a row: a crusher run's product.csv as it is.
std::vector<double> readDiameterRadii(TableReader& t, const std::filesystem::path& base_dir) {
  const std::filesystem::path file = base_dir / t.requiredString("diameters_file");
  std::ifstream in(file);
  if (!in) t.fail("diameters_file", "cannot read " + file.string());
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::stringstream cells(line); std::getline(cells, line, ',');) header.push_back(line);
  const auto column = std::find_if(header.begin(), header.end(),
                                   [](const std::string& h) { return h == "diameter_mm" || h == "diameter_m"; });
  if (column == header.end())
    t.fail("diameters_file", file.string() + ": its first line names no diameter_mm or diameter_m column");
  const auto index = static_cast<std::size_t>(column - header.begin());
  const double to_radius = *column == "diameter_mm" ? 0.5e-3 : 0.5;
  std::vector<double> radii;
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.empty()) continue;
    std::vector<std::string> cells;
    for (std::stringstream split(line); std::getline(split, line, ',');) cells.push_back(line);
    double d = 0;
    std::size_t used = 0;
    try {
      d = index < cells.size() ? std::stod(cells[index], &used) : 0.0;
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != cells[index].size() || !(d > 0) || !std::isfinite(d))
      t.fail("diameters_file", file.string() + " line " + std::to_string(row) + ": the " + *column + " '" +
                                   (index < cells.size() ? cells[index] : std::string()) +
                                   "' is not a positive number");
    radii.push_back(to_radius * d);
  }
  if (radii.empty()) t.fail("diameters_file", file.string() + " holds no diameters");
  return radii;
}

}  // namespace

void readParticles(TableReader& root, const std::map<std::string, int>& materials,
                   const std::vector<sim::Material>& material_list, std::uint64_t seed,
                   const std::filesystem::path& base_dir, Scene& scene) {
  std::vector<sim::SphereSpec>& spheres = scene.spheres;
  std::size_t source_index = 0;
  // Every ball placed so far (clump members in world position), for insertion.
  std::vector<geometry::Sphere> placed;
  for (TableReader t : root.tableArray("particles")) {
    const std::string type = t.requiredString("type", {"lattice", "random", "list", "agglomerate", "agglomerates"});
    const int material = materialIndex(t, materials);
    if (type == "agglomerates") {
      geometry::Rng feed_rng(seed * 1000003ull + source_index);
      readAgglomerateFeed(t, material, feed_rng, placed, scene);
      t.finish();
      ++source_index;
      continue;
    }
    if (type == "agglomerate") {
      geometry::Rng agglomerate_rng(seed * 1000003ull + source_index);
      readAgglomerate(t, material, base_dir, agglomerate_rng, scene);
      for (std::size_t k = scene.agglomerates.back().first_ball; k < spheres.size(); ++k)
        placed.push_back({spheres[k].position, spheres[k].radius});
      t.finish();
      ++source_index;
      continue;
    }
    const Vec3 velocity = t.vec3("velocity", Vec3::Zero());
    const std::string shape = t.string("shape", "sphere", {"sphere", "four_ball", "file"});
    // Each source has its own stream, so adding a source does not move the
    // others.
    geometry::Rng rng(seed * 1000003ull + source_index);
    BodyShape body;
    if (shape != "sphere") {
      ClumpShapeReport report;
      report.source = t.path();
      body = readClumpShape(t, shape, material_list[static_cast<std::size_t>(material)].density,
                            base_dir, report);
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
      const auto lk = kind == "sc"    ? geometry::LatticeKind::SimpleCubic
                      : kind == "bcc" ? geometry::LatticeKind::BodyCentred
                                      : geometry::LatticeKind::FaceCentred;
      const double per_cell = kind == "sc" ? 1 : kind == "bcc" ? 2 : 4;
      checkBallBudget(t, "counts", per_cell * counts.prod(),
                      clumps ? static_cast<double>(body.members.size()) : 1.0, ballsSoFar(scene));
      points = geometry::latticePoints(lk, cell, offset, corner, n);
      radii.assign(points.size(), radius);
    } else if (type == "random") {
      const Vec3 lo = t.requiredVec3("region_min"), hi = t.requiredVec3("region_max");
      double r_min = 0, r_max = 0, body_volume = 0;
      const bool from_file = t.has("diameters_file");
      if (clumps && from_file) t.fail("diameters_file", "sizes spheres only (shape = \"sphere\")");
      if (from_file) {
        radii = readDiameterRadii(t, base_dir);
        r_min = *std::min_element(radii.begin(), radii.end());
        r_max = *std::max_element(radii.begin(), radii.end());
        double r3 = 0;
        for (const double r : radii) r3 += r * r * r / static_cast<double>(radii.size());
        body_volume = 4.0 / 3.0 * std::numbers::pi * r3;
        if (!((hi - lo).minCoeff() > 2 * r_max)) t.fail("region_max", "the region must be wider than a sphere");
      } else if (clumps) {
        body_volume = scene.clump_shapes.back().union_volume;
      } else {
        if (t.has("radius")) {
          r_min = r_max = t.number("radius", 0, Range::positive());
        } else {
          r_min = t.requiredNumber("radius_min", Range::positive());
          r_max = t.requiredNumber("radius_max", Range::positive());
          if (r_max < r_min) t.fail("radius_max", "must be >= radius_min");
        }
        if (!((hi - lo).minCoeff() > 2 * r_max))
          t.fail("region_max", "the region must be wider than a sphere");
        // Mean volume of radii uniform in [r_min, r_max]: (4/3) pi <r^3>.
        const double mean_r3 =
            r_max > r_min ? (std::pow(r_max, 4) - std::pow(r_min, 4)) / (4 * (r_max - r_min))
                          : std::pow(r_min, 3);
        body_volume = 4.0 / 3.0 * std::numbers::pi * mean_r3;
      }
      if (from_file && (t.has("count") || t.has("solid_fraction")))
        t.fail(t.has("count") ? "count" : "solid_fraction", "diameters_file gives the spheres: one a row");
      if (!from_file && t.has("count") == t.has("solid_fraction"))
        t.fail("count",
               "give exactly one of count (particles) and "
               "solid_fraction (of the region volume, "
               "so that a size sweep fills the same space)");
      std::int64_t count = from_file ? static_cast<std::int64_t>(radii.size())
                                     : t.integer("count", 0, Range::closed(1, kMaxBalls));
      const double region = (hi - lo).cwiseMax(Vec3::Zero()).prod();
      if (t.has("solid_fraction")) {
        const double f = t.number("solid_fraction", 0, {0.0, 1.0, true, true});
        if (f > kRandomInsertionReach) {
          std::ostringstream what;
          what << "above what random insertion reaches: it places bodies one by one without overlap and fills "
                  "about 0.27 of a region with equal spheres, less with a size range or clumps (at most "
               << kRandomInsertionReach
               << " is accepted); for a denser pack use a lattice or let a looser one settle under gravity";
          t.fail("solid_fraction", what.str());
        }
        const double bodies = std::floor(f * region / body_volume);
        checkBallBudget(t, "solid_fraction", bodies, clumps ? static_cast<double>(body.members.size()) : 1.0,
                        ballsSoFar(scene));
        count = static_cast<std::int64_t>(bodies);
        if (count < 1) t.fail("solid_fraction", "gives no particle in this region");
      } else {
        checkBallBudget(t, from_file ? "diameters_file" : "count", static_cast<double>(count),
                        clumps ? static_cast<double>(body.members.size()) : 1.0, ballsSoFar(scene));
      }
      // What the bodies placed fill of the region, for the message when they stop short.
      auto reached = [&](std::size_t placed_bodies) {
        std::ostringstream s;
        s << " (random insertion stopped at a solid fraction of " << std::setprecision(2)
          << static_cast<double>(placed_bodies) * body_volume / region << " of the region)";
        return s.str();
      };
      if (clumps) {
        const std::vector<const std::vector<geometry::Sphere>*> shapes(
            static_cast<std::size_t>(count), &body.members);
        const auto poses = geometry::randomNonOverlappingBodies(shapes, lo, hi, placed, rng);
        if (poses.size() < shapes.size())
          t.fail(t.has("count") ? "count" : "solid_fraction",
                 "only " + std::to_string(poses.size()) + " of " + std::to_string(shapes.size()) +
                     " clumps fit in the region without overlap" + reached(poses.size()) + "; enlarge "
                     "region_min/region_max or ask for fewer");
        for (const auto& pose : poses) {
          points.push_back(pose.position);
          orientations.push_back(pose.orientation);
        }
      } else {
        if (!from_file)
          for (std::int64_t k = 0; k < count; ++k) radii.push_back(rng.uniform(r_min, r_max));
        points = geometry::randomNonOverlapping(radii, lo, hi, placed, rng);
        if (points.size() < radii.size())
          t.fail(from_file ? "diameters_file" : t.has("count") ? "count" : "solid_fraction",
                 "only " + std::to_string(points.size()) + " of " + std::to_string(radii.size()) +
                     " spheres fit in the region without overlap" + reached(points.size()) + "; enlarge "
                     "region_min/region_max or ask for fewer");
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
      if (!omegas.empty() && omegas.size() != points.size())
        t.fail("omegas", "needs one per position");
    }
    // Clumps not placed by the random insertion get random orientations too.
    if (clumps && t.boolean("random_orientation", true))
      while (orientations.size() < points.size())
        orientations.push_back(geometry::randomRotation(rng));
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
        for (const auto& m : body.members)
          placed.push_back({points[k] + orientations[k] * m.centre, m.radius});
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

}  // namespace rocklab::experiments::detail
