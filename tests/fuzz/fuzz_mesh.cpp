// libFuzzer target: a particle scan or a mesh wall file. Input: one byte that
// picks the format (STL, PLY, OBJ by the file extension), then the file's
// bytes. It goes the two ways a mesh file is read: `rocklab shape`
// (readMeshFile + checkAndRepairMesh) and a [[walls]] type = "mesh"
// (importMesh + validate). Their errors are MeshCheckError and MeshImportError.
#include <cstdint>

#include "fuzz_support.h"
#include "rocklab/geometry/mesh_check.h"
#include "rocklab/geometry/mesh_import.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rocklab;
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".stl", ".ply", ".obj"};
  const auto file = fuzz::scratchDir() / (std::string("mesh") + kExtensions[data[0] % 3]);
  fuzz::writeFile(file, std::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
  try {
    geometry::MeshCheckReport report;
    (void)geometry::checkAndRepairMesh(geometry::readMeshFile(file.string(), 1.0), file.string(), report);
  } catch (const geometry::MeshCheckError&) {
  }
  try {
    (void)geometry::importMesh(file.string(), 1.0).validate();
  } catch (const geometry::MeshImportError&) {
  }
  return 0;
}
