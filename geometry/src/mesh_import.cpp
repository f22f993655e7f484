#include "rocklab/geometry/mesh_import.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "assimp_mesh.h"

namespace rocklab::geometry {

TriangleMesh importMesh(const std::string& path, double scale) {
  if (const std::string problem = detail::notAFile(path); !problem.empty())
    throw MeshImportError("cannot read mesh '" + path + "': " + problem);
  Assimp::Importer importer;
  // Per-face normals keep STL vertices apart; drop normals so that welding works.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices |
                aiProcess_PreTransformVertices);
  if (!scene || !scene->mRootNode)
    throw MeshImportError("cannot read mesh '" + path + "': " + importer.GetErrorString());
  TriangleMesh mesh = detail::trianglesOf(*scene, scale);
  if (mesh.triangles.empty())
    throw MeshImportError("mesh '" + path + "' contains no triangles");
  return mesh;
}

}  // namespace rocklab::geometry
