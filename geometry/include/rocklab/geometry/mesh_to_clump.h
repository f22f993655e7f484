#pragma once
// Mesh → clump: sets of overlapping spheres that stand for a closed particle surface,
// and how far such a set is from the surface it stands for.
//
// Two generators, from different families, sharing one greedy selection:
//
//  SurfaceSpheres — in the spirit of Ferellec & McDowell's expansion method
//    (experiments.md §h.5): at surface nodes (the mesh vertices plus area-weighted
//    random surface points) a sphere tangent to the surface is grown along the
//    inward normal n until it touches another node. For a node p with d = p − v,
//    the sphere centred at v + r n keeps p outside (allowing it to sit `touch_tolerance`
//    t inside, so scan noise does not pin the radius) while
//        |d|² − 2 r d·n + r² ≥ (r − t)²   ⇔   r ≤ (|d|² − t²) / (2 (d·n − t))   for d·n > t,
//    and r is the minimum of that bound over all nodes. The tolerance fixes the centre
//    c = v + r n; the candidate's radius is then what fits there (the distance from c to
//    the nearest node), and a chosen sphere is refined on the exact distance to the mesh
//    (centre moved up its gradient by at most max(t, 0.001 d_eq)), so it stays inscribed.
//  MedialAxis — centres of maximal inscribed balls on a voxel grid: the local maxima
//    of the distance transform (mesh_voxels.h), radius = distance to the surface.
//    A chosen ball's centre is then moved up the gradient of the exact distance to
//    the mesh (at most one grid cell: the grid places it only to ± h/2) and its radius
//    set to that exact distance.
//
// Greedy selection (both): candidates with radius >= min_radius; each step takes the
// candidate that covers the most inside grid cells not yet covered (lazy greedy: a
// candidate's gain can only shrink, so stale gains are upper bounds). It stops at
// max_spheres, when the true uncovered volume fraction is <= volume_tolerance, or
// when no candidate adds anything. The output is in selection order, so its first
// k spheres are what the method gives for k spheres.
#include <cstdint>
#include <string>
#include <vector>

#include "rocklab/geometry/mesh_properties.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

enum class ClumpMethod { SurfaceSpheres, MedialAxis };

struct MeshToClumpOptions {
  ClumpMethod method = ClumpMethod::SurfaceSpheres;
  int max_spheres = 20;           // upper limit on the count
  double volume_tolerance = 0.0;  // stop when the uncovered inside fraction is <= this (0 = use max_spheres)
  // Lengths as fractions of the mesh's equivalent diameter d_eq (so one setting suits any size;
  // d_eq is taken from the inside grid's volume, ± a cell).
  double min_radius = 0.0;        // candidates with radius < min_radius d_eq are discarded (sets the DEM time step)
  // SurfaceSpheres: how deep a node may lie inside a sphere (t = touch_tolerance d_eq). Without it a
  // vertex normal a fraction of a degree off (an icosphere's are) lets the next vertex pin the radius.
  double touch_tolerance = 0.005;
  int grid_cells = 48;            // inside grid: cells along the largest extent
  int max_candidates = 2000;      // candidate spheres kept (evenly thinned)
  int surface_samples = 8000;     // random surface nodes added to the vertices
  std::uint64_t seed = 1;
};

/// Why the selection stopped.
enum class ClumpStop {
  Spheres,    // max_spheres reached
  Tolerance,  // the true uncovered fraction fell to volume_tolerance
  Covered,    // every inside grid cell covered: another sphere adds nothing the grid sees
  Exhausted,  // cells are left, but no candidate covers any of them (min_radius, grid)
};
const char* clumpStopReason(ClumpStop stop);

struct ClumpResult {
  std::vector<Sphere> spheres;  // in selection order, refined
  ClumpStop stop = ClumpStop::Spheres;
  double uncovered = 0;         // 1 − V_union / V_mesh at the stop (true volumes, not the grid's)
};

/// Spheres in selection order and why the selection stopped. With volume_tolerance
/// the stop test is the true uncovered fraction of the refined spheres (computed
/// once the grid's estimate passes the tolerance), so a clump that stops on the
/// tolerance is within it. Throws std::invalid_argument for bad options and
/// std::runtime_error when no candidate reaches min_radius.
ClumpResult meshToClumpWithStop(const TriangleMesh& mesh, const MeshToClumpOptions& options);

/// meshToClumpWithStop's spheres.
std::vector<Sphere> meshToClump(const TriangleMesh& mesh, const MeshToClumpOptions& options);

struct SurfacePoint {
  Vec3 point;
  Vec3 normal;  // outward unit normal of its triangle
};

/// `count` points spread uniformly by area over the surface (seeded).
std::vector<SurfacePoint> sampleSurface(const TriangleMesh& mesh, int count, std::uint64_t seed);

/// How well a sphere set stands for a mesh. Both are taken at the same uniform
/// density, so the errors are those of the shape alone.
struct ClumpFitError {
  std::size_t spheres = 0;
  double union_volume = 0;            // m^3, true union of the spheres (clumpMassProperties, Union)
  double volume_error = 0;            // (V_union − V_mesh) / V_mesh, signed
  double inertia_error = 0;           // max_i |I_union,i − I_mesh,i| / I_mesh,i, principal moments, same density
  double inertia_error_mass_scaled = 0;  // the same after scaling the union to the mesh's mass
  double surface_error_mean = 0;      // m, mean over surface samples of the distance to the clump surface
  double surface_error_max = 0;       // m, max of the same
};

/// Distance from a surface sample p to the clump surface is |min_k (|p − c_k| − r_k)|:
/// exact when p is outside the union, a lower bound when p is inside it.
ClumpFitError clumpFitError(const MeshMassProperties& mesh_props, const std::vector<Sphere>& spheres,
                            const std::vector<SurfacePoint>& samples, int resolution = 256);

}  // namespace rocklab::geometry
