#pragma once
// Mesh files (STL ascii/binary, PLY, OBJ, ...) read with assimp.
#include <stdexcept>
#include <string>

#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry {

struct MeshImportError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Reads every mesh in the file into one triangle mesh, welding identical
/// vertices, and scales coordinates by `scale` (e.g. 0.001 for a file in mm).
/// Throws MeshImportError naming the file and assimp's reason.
TriangleMesh importMesh(const std::string& path, double scale = 1.0);

}  // namespace rocklab::geometry
