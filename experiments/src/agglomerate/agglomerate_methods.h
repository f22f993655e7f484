#pragma once
// One bonded agglomerate by one of the reference's methods (experiments.md §f):
//   dense  the servo-compacted (or geometric) loose pack of r_max spheres filling the
//          diameter (loose_pack.h), its voids filled down to r_max / r0 (fillVoids,
//          §f.4 steps 2-4), the spheres wholly inside the diameter kept;
//   hcp    hexagonal close packing of r_max spheres in the diameter, rotated by
//          angle_deg about z (§f.3);
//   mesh   a dense agglomerate at least as large as the placed mesh, carved by it
//          (spheres whose centres are inside, §f.7; carveByMesh).
// Bonds: every pair within the gap tolerance (bondPairs: gap <= gap_tolerance x the
// smaller radius). Centres are returned about the centre of mass (sphere volumes as
// weights, uniform density). Locked-in stress: locked_in_stress.h with the pack's
// material.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "agglomerate/locked_in_stress.h"
#include "agglomerate/loose_pack.h"
#include "rocklab/geometry/agglomerate_packing.h"
#include "rocklab/geometry/bond_pairs.h"
#include "rocklab/geometry/carve_by_mesh.h"
#include "rocklab/geometry/structure_statistics.h"
#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::experiments::agglomerate {

enum class Method { Dense, Hcp, Mesh };
Method parseMethod(const std::string& name);  // "dense" | "hcp" | "mesh"; invalid_argument
const char* methodName(Method method);

/// The particle surface of the mesh method, read and checked once for all agglomerates.
struct MeshSource {
  std::string file;
  geometry::TriangleMesh mesh;   // m, as read (unit applied), checked and repaired
  geometry::CarveOptions carve;  // size, measure, name
  std::vector<std::string> repairs;  // what the check repaired (one sentence each)
  double dense_diameter = 0.0;   // m  of the dense agglomerate it is carved from
};

/// Reads and checks `file` (coordinates times `metres_per_unit`), sizes it to `size`
/// (m, by `measure`; 0 = as read) and finds the diameter of the dense agglomerate:
/// twice the mesh's reach from its centroid plus 2 r_max (carving puts the mesh's
/// centroid on the spheres', which is near but not at the centre). Throws
/// geometry::MeshCheckError for an unreadable, open or non-manifold mesh; holes of
/// at most `fill_holes` edges are closed first (0: none).
MeshSource prepareMeshSource(const std::string& file, double metres_per_unit, double size,
                             geometry::MeshSizeMeasure measure, double r_max, double gap_tolerance,
                             std::size_t fill_holes = 0);

struct AgglomerateSpec {
  Method method = Method::Dense;
  double diameter = 0.05;       // m  (dense, hcp; mesh: from the MeshSource)
  double r_max = 0.0025;        // m
  double r0 = 4.0;              // -  r_max / r_min (Eq 5-11)
  double angle_deg = 0.0;       // hcp
  double gap_tolerance = 1e-3;  // -  of the smaller radius
  std::uint64_t seed = 1;
  LoosePackParams pack;              // dense, mesh: kind, first count, servo settings
  const MeshSource* mesh = nullptr;  // mesh method
};

struct GeneratedAgglomerate {
  std::vector<geometry::Sphere> spheres;  // about the centre of mass
  std::vector<geometry::SpherePair> bonds;
  geometry::StructureStatistics structure;  // porosity against the envelope
  LockedInStress locked_in;
  double diameter = 0.0;          // m  of the spherical agglomerate made (mesh: the dense one)
  std::optional<LoosePack> pack;  // dense, mesh (spheres moved out)
  std::optional<geometry::VoidFillReport> void_fill;
  double wall_time_s = 0.0;
};

GeneratedAgglomerate generateAgglomerate(const AgglomerateSpec& spec);

}  // namespace rocklab::experiments::agglomerate
