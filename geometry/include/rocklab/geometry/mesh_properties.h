#pragma once
// Exact mass properties of a closed triangle mesh of uniform density, and the shape
// descriptors a user picks a particle by.
//
// Mass properties by the divergence theorem (Eberly, "Polyhedral Mass Properties
// (Revisited)", 2002; the same sums as Mirtich 1996): each triangle and the origin
// span a signed tetrahedron whose integrals of 1, x, y, z, x², y², z², xy, yz, zx
// are polynomials in the corner coordinates; summed over a closed, outward surface
// they give the solid's integrals exactly (up to round-off). The mesh is shifted
// to its bounding-box centre first: scans sit metres off the origin and the second
// moments would otherwise cancel catastrophically. The inertia tensor carries the
// products with a minus sign, as in Eq 2-43/2-47.
#include "rocklab/geometry/triangle_mesh.h"
#include "rocklab/geometry/vec.h"

namespace rocklab::geometry {

struct MeshMassProperties {
  double volume = 0;                       // m^3 (negative if the surface faces inward)
  double area = 0;                         // m^2
  double mass = 0;                         // kg = density * volume
  Vec3 centroid = Vec3::Zero();            // m, mesh frame
  Mat3 inertia = Mat3::Zero();             // kg m^2 about the centroid, mesh axes (tensor with -products)
  Vec3 principal_moments = Vec3::Zero();   // kg m^2, ascending
  Mat3 principal_axes = Mat3::Identity();  // columns, mesh frame, right-handed (det +1)
};

/// Mass properties of a closed, outward-oriented mesh at `density` (kg/m^3).
MeshMassProperties meshMassProperties(const TriangleMesh& mesh, double density = 1.0);

struct ShapeDescriptors {
  // Extents along the principal axes, sorted: long L >= intermediate I >= short S (m).
  double long_dim = 0, intermediate_dim = 0, short_dim = 0;
  double elongation = 0;           // I / L (Zingg; 1 = not elongated)
  double flatness = 0;             // S / I (Zingg; 1 = not flat)
  double sphericity = 0;           // Wadell: area of the equal-volume sphere / area = π^(1/3) (6V)^(2/3) / A
  double equivalent_diameter = 0;  // m, diameter of the sphere of equal volume
  // m, the square sieve aperture the particle just passes, taken as sqrt((I² + S²)/2)
  // (the particle passing with its I–S section across the square's diagonal); an
  // approximation, no scan-based sieve simulation.
  double sieve_size = 0;
};

ShapeDescriptors shapeDescriptors(const TriangleMesh& mesh, const MeshMassProperties& props);

/// Mesh moved to its centroid and turned into its principal axes:
/// x_principal = axesᵀ (x − centroid). The canonical frame clumps are written in.
TriangleMesh toPrincipalFrame(const TriangleMesh& mesh, const MeshMassProperties& props);

/// Mesh scaled about the origin by `factor`.
TriangleMesh scaled(const TriangleMesh& mesh, double factor);

}  // namespace rocklab::geometry
