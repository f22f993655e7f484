#include "rocklab/geometry/mesh_import.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace rocklab::geometry {

TriangleMesh importMesh(const std::string& path, double scale) {
  Assimp::Importer importer;
  // Per-face normals keep STL vertices apart; drop normals so that welding works.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices |
                aiProcess_PreTransformVertices);
  if (!scene || !scene->mRootNode)
    throw MeshImportError("cannot read mesh '" + path + "': " + importer.GetErrorString());
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      mesh.vertices.emplace_back(scale * p.x, scale * p.y, scale * p.z);
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      mesh.triangles.push_back(
          {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  if (mesh.triangles.empty())
    throw MeshImportError("mesh '" + path + "' contains no triangles");
  return mesh;
}

}  // namespace rocklab::geometry
