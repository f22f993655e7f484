#pragma once
// Seeded, scan-like particle meshes (and analytic test solids), and writing meshes
// as STL (binary), PLY (ascii) or OBJ.
//
// Every particle generator is a star-shaped surface: the vertices of a subdivided
// icosahedron, each moved along its direction u to the radius ρ(u) of the particle.
// A star-shaped radius function over a closed, outward sphere mesh gives a closed,
// manifold, outward mesh without self-intersections, whatever ρ is (ρ > 0), so the
// generators never make a bad mesh.
//   pebble  — ellipsoid (axes 1 : 0.8 : 0.62) times a smooth bump field
//             1 + Σ a_k exp((u·d_k − 1)/w_k) (12 broad bumps of ±12 %, 60 fine ones of ±1.2 %): a rounded
//             river pebble;
//   crushed — the polytope of 10–14 random cutting planes (distance 0.75–1 from the
//             centre, normals random): ρ(u) = min over planes of d_k / (n_k·u); faces
//             flat, edges sharp up to the tessellation: angular crushed rock;
//   flake   — a crushed polytope squashed to 1 : 0.85 : 0.3 (flatness S/I ≈ 0.35).
// Sizes are arbitrary (about 1 across); `rocklab shape --size` scales them.
#include <cstdint>
#include <string>

#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

/// Icosahedron subdivided `level` times (20·4^level triangles), on a sphere of `radius`.
TriangleMesh icosphere(int level, double radius);

/// Axis-aligned box with corners lo, hi (12 triangles, outward).
TriangleMesh boxMesh(const Vec3& lo, const Vec3& hi);

/// Ellipsoid with semi-axes a, b, c (icosphere of `level` scaled per axis).
TriangleMesh ellipsoidMesh(double a, double b, double c, int level);

enum class ParticleKind { Pebble, Crushed, Flake };

/// Parses "pebble" | "crushed" | "flake"; throws std::invalid_argument otherwise.
ParticleKind parseParticleKind(const std::string& name);

/// A scan-like particle (see above), `level` icosphere subdivisions (4 → 5120 triangles).
TriangleMesh generateParticle(ParticleKind kind, std::uint64_t seed, int level = 4);

/// Writes the mesh; the format follows the extension: .stl (binary), .ply (ascii),
/// .obj. Written to "<path>.partial" and renamed. Throws std::runtime_error naming
/// the file (unknown extension, cannot write).
void writeMeshFile(const std::string& path, const TriangleMesh& mesh);

}  // namespace rocklab::geometry
