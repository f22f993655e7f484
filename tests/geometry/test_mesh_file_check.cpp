// Mesh files whose own counts, sizes or indices disagree with their contents are
// refused before assimp reads them (it aborts on some: a PLY header that
// under-states its vertex count), for both readers: particle scans and mesh walls.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "rocklab/geometry/mesh_check.h"
#include "rocklab/geometry/mesh_file_check.h"
#include "rocklab/geometry/mesh_import.h"

namespace fs = std::filesystem;
using rocklab::geometry::meshFileProblem;
using Catch::Contains;

namespace {

fs::path scratch() {
  const fs::path d = fs::temp_directory_path() / ("rocklab-meshfile-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

fs::path write(const std::string& name, const std::string& bytes) {
  const fs::path p = scratch() / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

/// An ascii PLY tetrahedron whose header declares `vertices` and `faces`.
std::string ply(int vertices, int faces, const std::string& body = "") {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
         "\nproperty list uchar int vertex_indices\nend_header\n" +
         (body.empty() ? "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n" : body);
}

std::string binaryStl(std::uint32_t declared, std::uint32_t written) {
  std::string s(80, ' ');
  s.append(reinterpret_cast<const char*>(&declared), 4);
  for (std::uint32_t t = 0; t < written; ++t) {
    const float f[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    s.append(reinterpret_cast<const char*>(f), sizeof f);
    s.append(2, '\0');
  }
  return s;
}

}  // namespace

TEST_CASE("a mesh file whose counts disagree with its contents is refused before assimp reads it", "[mesh]") {
  CHECK(meshFileProblem(write("good.ply", ply(4, 4)).string()).empty());
  CHECK(meshFileProblem(write("good.stl", binaryStl(2, 2)).string()).empty());
  CHECK(meshFileProblem(write("good.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1/1 2/2 -1\n").string()).empty());

  // Each: the file, and a piece of what the message must say.
  const std::pair<fs::path, std::string> bad[] = {
      {write("under.ply", ply(3, 4)), "under-state"},  // assimp: abort() in its triangulation
      {write("over.ply", ply(5, 4)), "more value(s) than the header's properties"},
      {write("short.ply", ply(4, 5)), "ends after 4 of the 5 'face' rows"},
      {write("extra.ply", ply(4, 3)), "data after the last row"},
      {write("index.ply", ply(4, 1, "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 9\n")), "refers to vertex 9"},
      {write("nan.ply", ply(4, 1, "0 0 0\nnan 0 0\n0 1 0\n0 0 1\n3 0 1 2\n")), "non-finite"},
      {write("huge.ply", ply(2000000000, 1)), "more than the 1e+07"},
      {write("truncated.stl", binaryStl(10, 3)), "says 10 triangles"},
      {write("empty.stl", binaryStl(0, 0)), "0 triangles"},
      {write("quad.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n"
                         "vertex 0 1 0\nendloop\nendfacet\nendsolid x\n"), "a facet with 4 vertices"},
      {write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), "face vertex '4'"},
      {write("line.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), "at least 3"},
      {write("mesh.off", "OFF\n"), "unknown extension"},
  };
  for (const auto& [file, says] : bad) {
    INFO(file.filename().string());
    CHECK_THAT(meshFileProblem(file.string()), Contains(says));
    // Both readers refuse it with the file named, instead of handing it to assimp.
    CHECK_THROWS_WITH(rocklab::geometry::readMeshFile(file.string(), 1.0), Contains(file.string()) && Contains(says));
    CHECK_THROWS_WITH(rocklab::geometry::importMesh(file.string(), 1.0), Contains(file.string()) && Contains(says));
  }
  fs::remove_all(scratch());
}

TEST_CASE("a face index past the vertices that the pre-check misses is refused after assimp reads it", "[mesh]") {
  // Found by fuzz_mesh (tests/fuzz/regressions/mesh/ply-face-index-past-the-vertices):
  // the last row lacks its line end, the pre-check counts it as a good face, and
  // assimp reads vertex 11 from it; the triangles were then indexed past the
  // vertices (a heap overflow under ASan). assimp's ValidateDataStructure step now
  // refuses it before any other step uses it.
  const fs::path file = write("eof-row.ply", ply(4, 4, "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 00 0 1\n3 0 2 1"));
  CHECK(meshFileProblem(file.string()).empty());
  // (Catch2's combined matchers hold their parts by reference: built inside each check.)
  const std::string says = "aiMesh::mFaces[3]::mIndices[2] is out of range";
  CHECK_THROWS_WITH(rocklab::geometry::readMeshFile(file.string(), 1.0), Contains(file.string()) && Contains(says));
  CHECK_THROWS_WITH(rocklab::geometry::importMesh(file.string(), 1.0), Contains(file.string()) && Contains(says));
  fs::remove_all(scratch());
}
