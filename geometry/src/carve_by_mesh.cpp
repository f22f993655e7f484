#include "rocklab/geometry/carve_by_mesh.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "parameter_check.h"
#include "rocklab/geometry/mesh_properties.h"
#include "rocklab/geometry/mesh_voxels.h"

namespace rocklab::geometry {

namespace {

double meshSize(const TriangleMesh& mesh, const MeshMassProperties& props,
                MeshSizeMeasure measure) {
  const ShapeDescriptors shape = shapeDescriptors(mesh, props);
  return measure == MeshSizeMeasure::SieveSize ? shape.sieve_size : shape.equivalent_diameter;
}

}  // namespace

CarveResult carveByMesh(const std::vector<Sphere>& spheres, const TriangleMesh& mesh,
                        const CarveOptions& options) {
  detail::requireParameter(options.size >= 0 && std::isfinite(options.size), "carveByMesh", "size",
                           options.size, "must be >= 0 (m; 0 = the mesh as given)");
  if (spheres.empty()) throw std::invalid_argument("carveByMesh: no spheres to carve");
  CarveResult out;
  TriangleMesh checked = checkAndRepairMesh(mesh, options.mesh_name, out.mesh_check);
  const MeshMassProperties props = meshMassProperties(checked);
  const double factor =
      options.size > 0 ? options.size / meshSize(checked, props, options.size_measure) : 1.0;
  // Scaled about its centroid, which goes onto the spheres' centroid.
  const Vec3 target = volumeCentroid(spheres);
  for (Vec3& v : checked.vertices) v = target + factor * (v - props.centroid);

  double mesh_reach = 0, pack_reach = 0;
  for (const Vec3& v : checked.vertices) mesh_reach = std::max(mesh_reach, (v - target).norm());
  for (const Sphere& s : spheres)
    pack_reach = std::max(pack_reach, (s.centre - target).norm() + s.radius);
  if (mesh_reach > pack_reach)
    throw std::invalid_argument(
        "carveByMesh: mesh '" + options.mesh_name + "' reaches " + detail::formatValue(mesh_reach) +
        " m from the centroid but the spheres only " + detail::formatValue(pack_reach) +
        " m: generate a larger agglomerate (or a smaller size)");

  std::vector<Vec3> centres;
  centres.reserve(spheres.size());
  for (const Sphere& s : spheres) centres.push_back(s.centre);
  const std::vector<bool> inside = pointsInside(checked, centres);
  for (std::size_t i = 0; i < spheres.size(); ++i)
    if (inside[i]) out.spheres.push_back(spheres[i]);
  out.structure = structureStatistics(out.spheres, props.volume * factor * factor * factor,
                                      options.gap_tolerance);
  out.placed_mesh = std::move(checked);
  return out;
}

}  // namespace rocklab::geometry
