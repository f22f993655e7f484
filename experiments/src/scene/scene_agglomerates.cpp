// Scene reader: [[particles]] of type "agglomerate", bonded spheres placed as
// one body (experiments.md §f): the hexagonal close packing of the anisotropy
// study (§f.3), every touching pair bonded.
#include <numbers>

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

void readAgglomerate(TableReader& t, int material, geometry::Rng& rng, Scene& scene) {
  AgglomerateReport report;
  report.source = t.path();
  report.method = t.string("method", "hcp", {"hcp"});
  const double radius = t.requiredNumber("radius", Range::positive());
  const double diameter = t.requiredNumber("diameter", Range::positive());
  if (diameter < 2 * radius) t.fail("diameter", "must be at least two sphere radii");
  // Layers stacked along y, turned by hcp_angle about z (§f.3): the angle
  // between the stacking axis and y, which the platens of a test along y see.
  const double angle = t.number("hcp_angle", 0.0, Range::closed(0, 90));
  const double gap_tolerance = t.number("gap_tolerance", 1e-3, Range::closed(0, 0.5));
  std::vector<geometry::Sphere> body;
  try {
    body = geometry::hcpPacking(radius, diameter, angle);
  } catch (const std::invalid_argument& e) {
    t.fail("radius", e.what());
  }
  if (body.size() > 2000000) t.fail("diameter", "gives more than 2e6 spheres");
  // The agglomerate's frame -> world: a fixed rotation (deg about x, y, z),
  // followed by a random one (seeded) when orientation = "random", then the centre.
  geometry::Quat q = rotationFromDegrees(t.vec3("rotation", Vec3::Zero()));
  if (t.string("orientation", "given", {"given", "random"}) == "random") q = geometry::randomRotation(rng) * q;
  const Vec3 centre = t.requiredVec3("position");
  const Vec3 velocity = t.vec3("velocity", Vec3::Zero());

  const std::vector<geometry::SpherePair> pairs = geometry::bondPairs(body, gap_tolerance);
  const geometry::StructureStatistics stats = geometry::structureStatistics(
      body, std::numbers::pi / 6.0 * diameter * diameter * diameter, gap_tolerance);
  report.first_ball = scene.spheres.size();
  report.balls = body.size();
  report.first_bond = scene.bonds.size();
  report.bonds = pairs.size();
  report.diameter = diameter;
  report.porosity = stats.porosity;
  report.coordination_number = stats.coordination_number;
  report.solid_volume = stats.solid_volume;
  for (const geometry::Sphere& s : body) {
    sim::SphereSpec spec;
    spec.position = centre + q * s.centre;
    spec.radius = s.radius;
    spec.velocity = velocity;
    spec.material = material;
    scene.spheres.push_back(spec);
  }
  for (const auto& [a, b] : pairs) {
    sim::BondSpec bond;
    bond.a = static_cast<std::uint32_t>(report.first_ball + a);
    bond.b = static_cast<std::uint32_t>(report.first_ball + b);
    scene.bonds.push_back(bond);
  }
  scene.agglomerates.push_back(report);
}

}  // namespace rocklab::experiments::detail
