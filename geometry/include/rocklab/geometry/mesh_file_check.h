#pragma once
// A mesh file's structure checked before assimp reads it. assimp trusts a file's
// own counts: a PLY whose header under-states its vertex count makes it abort()
// (an assertion in its triangulation), one that over-states it reads garbage. So
// every STL, PLY and OBJ is pre-parsed here, and only a file whose counts, sizes,
// numbers and indices agree is handed on: rows against the header's counts (PLY),
// the byte size against the triangle count (binary STL), three vertices a facet
// (ascii STL), face indices against the vertices (PLY, OBJ), finite coordinates.
#include <string>

namespace rocklab::geometry {

/// The most triangles (and vertices) a mesh file may hold: ~100 bytes each while
/// read, so about 1 GB; a particle scan has 10^4 to 10^5, a wall far fewer.
constexpr double kMaxMeshFileTriangles = 1e7;

/// "" when `path` is an STL (ascii or binary), PLY (ascii or binary) or OBJ file whose
/// structure is consistent; else one sentence saying what is wrong and where (row,
/// line or byte), without the path (the caller names the file).
std::string meshFileProblem(const std::string& path);

}  // namespace rocklab::geometry
