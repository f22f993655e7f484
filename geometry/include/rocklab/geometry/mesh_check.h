#pragma once
// Reading a scanned particle surface and making it fit for mass properties and
// clump building: every class of bad scan gets a message, and what can be repaired
// without guessing is repaired and reported.
//
// Why our own welding: assimp's JoinIdenticalVertices works inside one aiMesh
// only (an OBJ with several groups stays unwelded) and needs the per-face normals
// of STL removed first. Topology checks need one vertex per position across the
// whole file, so vertices are welded here by exact coordinates (after unit scaling
// is applied to all alike). Exact, not tolerant, welding: a tolerance would collapse
// small features and could hide real gaps that the closedness check must see.
//
// Policy (a scan is rarely perfect; a clump needs a closed surface):
//   errors (MeshCheckError, nothing written): file missing/unreadable, no triangles,
//     open boundary edges, non-manifold edges, a shell that cannot be oriented;
//   repaired only when asked (`fill_holes_up_to` > 0): holes whose boundary is a
//     simple loop of at most that many edges, closed by a minimum-area patch (CGAL);
//   repaired with a warning: collapsed triangles (a repeated vertex) removed,
//     inconsistent orientation fixed (each shell to its majority, flipped count
//     reported), inward normals (negative volume) flipped, several shells (the
//     largest by volume kept, the others dropped);
//   warning only: zero-area triangles (kept: they close the topology and add no
//     volume).
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

struct MeshCheckError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct MeshCheckReport {
  std::size_t input_triangles = 0;      // as read (after triangulation)
  std::size_t vertices = 0;             // after welding
  std::size_t collapsed_removed = 0;    // triangles with a repeated vertex, removed
  std::size_t zero_area = 0;            // zero-area triangles (kept)
  std::size_t holes_filled = 0;         // boundary loops closed by a patch (when asked)
  std::size_t hole_triangles_added = 0; // the patches' triangles
  std::size_t boundary_edges = 0;       // edges used by one triangle (after any patch)
  std::size_t nonmanifold_edges = 0;    // edges used by more than two triangles
  std::size_t flipped_inconsistent = 0; // triangles flipped to agree with their shell
  bool flipped_inward = false;          // the kept shell was inside out and was flipped
  std::size_t shells = 0;               // connected components (by shared edges)
  std::size_t dropped_triangles = 0;    // triangles of the shells not kept
  std::vector<std::string> warnings;    // one sentence each, what was found and done
};

/// Reads a mesh file (STL ascii/binary, PLY, OBJ, ... whatever assimp reads),
/// scales coordinates by `scale` (0.001 for mm) and welds identical positions.
/// Throws MeshCheckError naming the file: missing, unreadable, no triangles.
TriangleMesh readMeshFile(const std::string& path, double scale);

/// Checks and repairs a welded mesh (see the policy above). `name` goes into every
/// message (usually the file path). Holes of at most `fill_holes_up_to` boundary
/// edges are closed first (0: none). Throws MeshCheckError for the error classes;
/// returns the repaired single closed, outward-oriented shell.
TriangleMesh checkAndRepairMesh(const TriangleMesh& mesh, const std::string& name, MeshCheckReport& report,
                                std::size_t fill_holes_up_to = 0);

/// Welds vertices with identical coordinates and renumbers triangles.
TriangleMesh weldIdenticalVertices(const TriangleMesh& mesh);

}  // namespace rocklab::geometry
