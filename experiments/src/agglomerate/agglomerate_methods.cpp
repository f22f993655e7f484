#include "agglomerate/agglomerate_methods.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "rocklab/geometry/hcp_packing.h"
#include "rocklab/geometry/mesh_check.h"
#include "rocklab/geometry/mesh_properties.h"

namespace rocklab::experiments::agglomerate {

namespace {

using geometry::Sphere;
using geometry::Vec3;

double sphereVolume(double radius) {
  return 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
}

void moveToCentreOfMass(std::vector<Sphere>& spheres) {
  const Vec3 centre = geometry::volumeCentroid(spheres);
  for (Sphere& s : spheres) s.centre -= centre;
}

struct Dense {
  std::vector<Sphere> spheres;
  LoosePack pack;
  geometry::VoidFillReport report;
};

Dense denseAgglomerate(const AgglomerateSpec& spec, double diameter) {
  LoosePackParams lp = spec.pack;
  lp.diameter = diameter;
  lp.seed = spec.seed;
  lp.servo.radius = spec.r_max;
  Dense d;
  d.pack = loosePackForDiameter(lp);
  geometry::VoidFillParams vf;
  vf.r_max = spec.r_max;
  vf.r0 = spec.r0;
  vf.agglomerate_radius = 0.5 * diameter;
  vf.gap_tolerance = spec.gap_tolerance;
  vf.seed = spec.seed;
  geometry::VoidFillResult filled = geometry::fillVoids(d.pack.spheres, vf);
  d.pack.spheres.clear();
  d.spheres = std::move(filled.spheres);
  d.report = filled.report;
  return d;
}

}  // namespace

Method parseMethod(const std::string& name) {
  if (name == "dense") return Method::Dense;
  if (name == "hcp") return Method::Hcp;
  if (name == "mesh") return Method::Mesh;
  throw std::invalid_argument("unknown method '" + name + "' (allowed: dense, hcp, mesh)");
}

const char* methodName(Method method) {
  switch (method) {
    case Method::Dense:
      return "dense";
    case Method::Hcp:
      return "hcp";
    case Method::Mesh:
      return "mesh";
  }
  return "?";
}

MeshSource prepareMeshSource(const std::string& file, double metres_per_unit, double size,
                             geometry::MeshSizeMeasure measure, double r_max,
                             double gap_tolerance, std::size_t fill_holes) {
  MeshSource m;
  m.file = file;
  geometry::MeshCheckReport report;
  // Checked (and repaired) once: each agglomerate's carve then checks a closed mesh.
  m.mesh = geometry::checkAndRepairMesh(geometry::readMeshFile(file, metres_per_unit), file, report, fill_holes);
  m.repairs = report.warnings;
  const geometry::TriangleMesh& checked = m.mesh;
  const geometry::MeshMassProperties props = geometry::meshMassProperties(checked);
  const geometry::ShapeDescriptors shape = geometry::shapeDescriptors(checked, props);
  const double current = measure == geometry::MeshSizeMeasure::SieveSize
                             ? shape.sieve_size
                             : shape.equivalent_diameter;
  const double factor = size > 0 ? size / current : 1.0;
  double reach = 0;
  for (const Vec3& v : checked.vertices) reach = std::max(reach, (v - props.centroid).norm());
  m.carve.size = size;
  m.carve.size_measure = measure;
  m.carve.mesh_name = file;
  m.carve.gap_tolerance = gap_tolerance;
  m.dense_diameter = 2.0 * factor * reach + 2.0 * r_max;
  return m;
}

GeneratedAgglomerate generateAgglomerate(const AgglomerateSpec& spec) {
  const auto t0 = std::chrono::steady_clock::now();
  GeneratedAgglomerate g;
  double envelope = 0;
  switch (spec.method) {
    case Method::Hcp:
      g.diameter = spec.diameter;
      g.spheres = geometry::hcpPacking(spec.r_max, spec.diameter, spec.angle_deg);
      envelope = sphereVolume(0.5 * spec.diameter);
      break;
    case Method::Dense: {
      g.diameter = spec.diameter;
      Dense d = denseAgglomerate(spec, spec.diameter);
      g.spheres = std::move(d.spheres);
      g.pack = std::move(d.pack);
      g.void_fill = d.report;
      envelope = sphereVolume(0.5 * spec.diameter);
      break;
    }
    case Method::Mesh: {
      if (!spec.mesh) throw std::invalid_argument("agglomerate: the mesh method needs a mesh");
      g.diameter = spec.mesh->dense_diameter;
      Dense d = denseAgglomerate(spec, g.diameter);
      geometry::CarveResult carved =
          geometry::carveByMesh(d.spheres, spec.mesh->mesh, spec.mesh->carve);
      g.spheres = std::move(carved.spheres);
      g.pack = std::move(d.pack);
      g.void_fill = d.report;
      envelope = carved.structure.envelope_volume;
      break;
    }
  }
  if (g.spheres.empty()) throw std::invalid_argument("agglomerate: no spheres were made");
  moveToCentreOfMass(g.spheres);
  g.bonds = geometry::bondPairs(g.spheres, spec.gap_tolerance);
  g.structure = geometry::structureStatistics(g.spheres, envelope, spec.gap_tolerance);
  const PackMaterial& mat = spec.pack.servo.material;
  g.locked_in = lockedInStress(g.spheres, g.bonds, mat.shear_modulus, mat.poisson, envelope);
  g.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

}  // namespace rocklab::experiments::agglomerate
