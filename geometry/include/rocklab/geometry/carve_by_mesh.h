#pragma once
// An irregular agglomerate carved from a spherical one by a scanned particle surface
// (experiments.md §f.7): the spheres whose centres lie inside the closed mesh are
// kept, the others deleted.
#include <string>
#include <vector>

#include "rocklab/geometry/mesh_check.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/structure_statistics.h"
#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

enum class MeshSizeMeasure { EquivalentDiameter, SieveSize };

struct CarveOptions {
  double size = 0;  // m, the mesh is scaled about its centroid to this size (0 = as given)
  MeshSizeMeasure size_measure = MeshSizeMeasure::EquivalentDiameter;  // which size `size` is
  std::string mesh_name = "mesh";                                      // named in every message
  double gap_tolerance = 1e-3;  // bond gap of the structure statistics
};

struct CarveResult {
  std::vector<Sphere> spheres;    // the kept ones, in input order
  TriangleMesh placed_mesh;       // the checked mesh as placed (and scaled) over the spheres
  MeshCheckReport mesh_check;     // repairs made (warnings)
  StructureStatistics structure;  // porosity against the placed mesh's volume
};

/// Keeps the spheres whose centres are inside `mesh`. The mesh is checked first
/// (checkAndRepairMesh: a mesh that is not closed or not manifold throws
/// MeshCheckError naming the problem and `mesh_name`), optionally scaled about its
/// centroid to `size`, and moved centroid to centroid: its volume centroid onto the
/// volume-weighted centroid of the spheres. Throws std::invalid_argument when size < 0,
/// when there are no spheres, or when the placed mesh reaches beyond the spheres (the
/// agglomerate must be generated larger than the particle).
CarveResult carveByMesh(const std::vector<Sphere>& spheres, const TriangleMesh& mesh,
                        const CarveOptions& options);

}  // namespace rocklab::geometry
