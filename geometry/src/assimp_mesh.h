#pragma once
// The triangles of every mesh of an assimp scene as one TriangleMesh (vertices
// scaled; faces that are not triangles — points, lines — skipped). Shared by
// importMesh (mesh walls) and readMeshFile (particle scans). Internal.
#include <cstdint>
#include <filesystem>
#include <string>

#include <assimp/scene.h>

#include "rocklab/geometry/triangle_mesh.h"

namespace rocklab::geometry::detail {

/// "" or why `path` cannot be a mesh file before assimp sees it (assimp says
/// only "No suitable reader found" for a folder).
inline std::string notAFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return "does not exist";
  if (std::filesystem::is_directory(path, ec)) return "is a directory, not a mesh file";
  return {};
}

/// The triangles of an assimp scene. Its readers run aiProcess_ValidateDataStructure
/// first, so every face index is within its mesh's vertices here.
inline TriangleMesh trianglesOf(const aiScene& scene, double scale) {
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* am = scene.mMeshes[m];
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      mesh.vertices.emplace_back(scale * p.x, scale * p.y, scale * p.z);
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      mesh.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  return mesh;
}

}  // namespace rocklab::geometry::detail
