#include "rocklab/geometry/mesh_import.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "assimp_mesh.h"
#include "rocklab/geometry/mesh_file_check.h"

namespace rocklab::geometry {

TriangleMesh importMesh(const std::string& path, double scale) {
  // assimp aborts on some malformed files: only a file whose structure agrees with
  // its own counts is handed to it.
  if (const std::string problem = meshFileProblem(path); !problem.empty())
    throw MeshImportError("cannot read mesh '" + path + "': " + problem);
  Assimp::Importer importer;
  // Per-face normals keep STL vertices apart; drop normals so that welding works.
  // ValidateDataStructure first: assimp's own check of what its reader made (a face
  // index past the vertices would otherwise reach JoinIdenticalVertices).
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_RemoveComponent |
                aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices);
  if (!scene || !scene->mRootNode)
    throw MeshImportError("cannot read mesh '" + path + "': " + importer.GetErrorString());
  TriangleMesh mesh = detail::trianglesOf(*scene, scale);
  if (mesh.triangles.empty())
    throw MeshImportError("mesh '" + path + "' contains no triangles");
  return mesh;
}

}  // namespace rocklab::geometry
