#include "rocklab/geometry/mesh_check.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "assimp_mesh.h"
#include "hole_fill.h"
#include "mesh_edges.h"
#include "rocklab/geometry/mesh_file_check.h"

namespace rocklab::geometry {

namespace {

using Tri = std::array<std::uint32_t, 3>;

using detail::EdgeUse;
using detail::edgeUses;

/// Edges a message names (where to look in the scan), at most.
constexpr std::size_t kEdgesNamed = 3;

/// ", e.g. at (x, y, z)-(x, y, z), ..." for the edges `keys` (lo << 32 | hi) of `count`.
std::string edgeList(const std::vector<Vec3>& v, const std::vector<std::uint64_t>& keys, std::size_t count) {
  std::ostringstream s;
  s.precision(4);
  const auto point = [&s, &v](std::uint64_t index) {
    const Vec3& p = v[static_cast<std::size_t>(index)];
    s << '(' << p.x() << ", " << p.y() << ", " << p.z() << ')';
  };
  s << (count > keys.size() ? ", e.g. at " : " at ");
  for (std::size_t k = 0; k < keys.size(); ++k) {
    s << (k ? ", " : "");
    point(keys[k] >> 32);
    s << '-';
    point(keys[k] & 0xffffffffu);
  }
  s << " m";
  return s.str();
}

double signedVolume(const std::vector<Vec3>& v, const std::vector<Tri>& tris, const std::vector<std::uint32_t>& which) {
  // Divergence theorem: sum of signed tetrahedra (origin, a, b, c).
  double six_v = 0;
  for (std::uint32_t t : which) six_v += v[tris[t][0]].dot(v[tris[t][1]].cross(v[tris[t][2]]));
  return six_v / 6.0;
}

}  // namespace

TriangleMesh weldIdenticalVertices(const TriangleMesh& mesh) {
  std::map<std::array<double, 3>, std::uint32_t> index;
  std::vector<std::uint32_t> remap(mesh.vertices.size());
  TriangleMesh out;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& p = mesh.vertices[i];
    const auto [it, inserted] = index.try_emplace({p.x(), p.y(), p.z()}, static_cast<std::uint32_t>(out.vertices.size()));
    if (inserted) out.vertices.push_back(p);
    remap[i] = it->second;
  }
  out.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) out.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  return out;
}

TriangleMesh readMeshFile(const std::string& path, double scale) {
  if (const std::string problem = detail::notAFile(path); !problem.empty())
    throw MeshCheckError("mesh file '" + path + "' " + problem);
  if (!std::ifstream(path).good()) throw MeshCheckError("mesh file '" + path + "' cannot be opened for reading");
  // assimp aborts on some malformed files: only a file whose structure agrees with
  // its own counts is handed to it.
  if (const std::string problem = meshFileProblem(path); !problem.empty())
    throw MeshCheckError("mesh file '" + path + "' cannot be read: " + problem);
  Assimp::Importer importer;
  // No JoinIdenticalVertices here: welding is done below across all meshes of the file.
  // ValidateDataStructure first: assimp's own check of what its reader made (a face
  // index past the vertices, from a damaged file) before any step uses it.
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (!scene || !scene->mRootNode)
    throw MeshCheckError("mesh file '" + path + "' cannot be read (STL ascii/binary, PLY and OBJ are supported): " +
                         importer.GetErrorString());
  TriangleMesh soup = detail::trianglesOf(*scene, scale);
  if (soup.triangles.empty()) throw MeshCheckError("mesh file '" + path + "' contains no triangles");
  // Before welding: NaN breaks the ordering the weld relies on.
  if (const std::string bad = soup.nonFiniteVertex(); !bad.empty())
    throw MeshCheckError("mesh file '" + path + "': " + bad);
  return weldIdenticalVertices(soup);
}

TriangleMesh checkAndRepairMesh(const TriangleMesh& mesh, const std::string& name, MeshCheckReport& report,
                                std::size_t fill_holes_up_to) {
  const std::string where = "mesh '" + name + "': ";
  report = MeshCheckReport{};
  report.input_triangles = mesh.triangles.size();
  report.vertices = mesh.vertices.size();
  if (mesh.triangles.empty()) throw MeshCheckError(where + "contains no triangles");
  if (const std::string bad = mesh.nonFiniteVertex(); !bad.empty()) throw MeshCheckError(where + bad);
  for (const Tri& t : mesh.triangles)
    for (std::uint32_t i : t)
      if (i >= mesh.vertices.size()) throw MeshCheckError(where + "a triangle refers to a vertex that does not exist");

  // 1. Degenerate triangles: collapsed ones (a repeated vertex) have no three edges
  //    and are removed; zero-area ones with three distinct vertices are kept.
  std::vector<Tri> tris;
  for (const Tri& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      ++report.collapsed_removed;
      continue;
    }
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    if (!((b - a).cross(c - a).squaredNorm() > 0)) ++report.zero_area;
    tris.push_back(t);
  }
  if (tris.empty()) throw MeshCheckError(where + "every triangle is degenerate (repeated vertices): no surface");
  if (report.collapsed_removed)
    report.warnings.push_back(std::to_string(report.collapsed_removed) +
                              " degenerate triangles (two corners at the same point) removed");
  if (report.zero_area)
    report.warnings.push_back(std::to_string(report.zero_area) +
                              " degenerate triangles of zero area (collinear corners) kept; they add no volume");

  // 1b. Small holes closed, when asked: a scan that misses a few triangles.
  if (fill_holes_up_to > 0) {
    const detail::HoleFill fill = detail::fillSmallHoles(mesh.vertices, tris, fill_holes_up_to);
    report.holes_filled = fill.holes_filled;
    report.hole_triangles_added = fill.triangles_added;
    if (fill.holes_filled)
      report.warnings.push_back(std::to_string(fill.holes_filled) + " holes of at most " +
                                std::to_string(fill.largest_filled) + " edges closed by " +
                                std::to_string(fill.triangles_added) + " patch triangles");
  }

  // 2. Edge topology: closed = every edge used exactly twice.
  const std::vector<EdgeUse> uses = edgeUses(tris);
  std::vector<std::vector<std::pair<std::uint32_t, bool>>> neighbours(tris.size());  // (triangle, same direction)
  std::vector<std::uint64_t> open_edges, nonmanifold_edges;  // the first few, to say where
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    const std::size_t n = j - i;
    if (n == 1 && ++report.boundary_edges <= kEdgesNamed) open_edges.push_back(uses[i].key);
    if (n > 2 && ++report.nonmanifold_edges <= kEdgesNamed) nonmanifold_edges.push_back(uses[i].key);
    if (n == 2) {
      const EdgeUse &x = uses[i], &y = uses[i + 1];
      const bool same = x.forward == y.forward;  // same direction = orientations disagree
      neighbours[x.triangle].push_back({y.triangle, same});
      neighbours[y.triangle].push_back({x.triangle, same});
    }
    i = j;
  }
  if (report.boundary_edges || report.nonmanifold_edges) {
    std::ostringstream msg;
    msg << where;
    if (report.boundary_edges)
      msg << "not closed: " << report.boundary_edges
          << " open boundary edges (edges of only one triangle: holes or cracks)"
          << edgeList(mesh.vertices, open_edges, report.boundary_edges);
    if (report.boundary_edges && report.nonmanifold_edges) msg << "; ";
    if (report.nonmanifold_edges)
      msg << report.nonmanifold_edges << " non-manifold edges (shared by more than two triangles)"
          << edgeList(mesh.vertices, nonmanifold_edges, report.nonmanifold_edges);
    msg << ". A clump needs one closed, manifold surface: repair the scan (e.g. close holes, "
           "remove duplicate faces) and try again";
    if (report.boundary_edges)
      msg << (fill_holes_up_to > 0 ? " (--fill-holes " + std::to_string(fill_holes_up_to) +
                                         " closed what it could: the rest are larger holes or touch each other)"
                                   : " (--fill-holes N closes holes of up to N edges)");
    throw MeshCheckError(msg.str());
  }

  // 3. Shells and orientation: breadth-first over shared edges; a neighbour whose
  //    shared edge runs the same way must be flipped relative to its parent.
  std::vector<int> shell(tris.size(), -1);
  std::vector<char> flip(tris.size(), 0);
  std::vector<std::vector<std::uint32_t>> members;
  for (std::uint32_t seed = 0; seed < tris.size(); ++seed) {
    if (shell[seed] >= 0) continue;
    const int s = static_cast<int>(members.size());
    members.emplace_back();
    std::vector<std::uint32_t> queue{seed};
    shell[seed] = s;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const std::uint32_t t = queue[q];
      members[s].push_back(t);
      for (const auto& [u, same] : neighbours[t]) {
        const char want = static_cast<char>(flip[t] ^ (same ? 1 : 0));
        if (shell[u] < 0) {
          shell[u] = s;
          flip[u] = want;
          queue.push_back(u);
        } else if (flip[u] != want) {
          throw MeshCheckError(where + "a shell cannot be oriented consistently (a Moebius-like or "
                                       "self-touching surface); repair the scan");
        }
      }
    }
    // Majority rule: the fewer triangles are the wrongly oriented ones.
    std::size_t flipped = 0;
    for (std::uint32_t t : members[s]) flipped += flip[t];
    if (2 * flipped > members[s].size()) {
      for (std::uint32_t t : members[s]) flip[t] ^= 1;
      flipped = members[s].size() - flipped;
    }
    report.flipped_inconsistent += flipped;
  }
  for (std::uint32_t t = 0; t < tris.size(); ++t)
    if (flip[t]) std::swap(tris[t][1], tris[t][2]);
  if (report.flipped_inconsistent)
    report.warnings.push_back(std::to_string(report.flipped_inconsistent) +
                              " triangles were oriented against their neighbours and were flipped");

  // 4. Keep the largest shell (by |volume|); flip it if it is inside out.
  report.shells = members.size();
  std::size_t best = 0;
  double best_volume = 0;
  std::vector<double> volumes;
  for (std::size_t s = 0; s < members.size(); ++s) {
    volumes.push_back(signedVolume(mesh.vertices, tris, members[s]));
    if (std::abs(volumes[s]) > std::abs(best_volume)) {
      best_volume = volumes[s];
      best = s;
    }
  }
  if (!(std::abs(best_volume) > 0)) throw MeshCheckError(where + "encloses no volume (flat surface)");
  if (members.size() > 1) {
    report.dropped_triangles = tris.size() - members[best].size();
    std::ostringstream msg;
    msg << members.size() << " disconnected shells; kept the largest (" << members[best].size()
        << " triangles, " << std::abs(best_volume) << " m^3) and dropped " << members.size() - 1 << " ("
        << report.dropped_triangles << " triangles)";
    report.warnings.push_back(msg.str());
  }
  report.flipped_inward = best_volume < 0;
  if (report.flipped_inward) report.warnings.push_back("normals pointed inward (negative volume); all triangles flipped");

  // Compact: only the kept shell's vertices, numbered in order of first use.
  std::vector<std::uint32_t> kept = members[best];
  std::sort(kept.begin(), kept.end());
  std::vector<std::uint32_t> remap(mesh.vertices.size(), UINT32_MAX);
  TriangleMesh out;
  for (std::uint32_t t : kept) {
    Tri tri = tris[t];
    if (report.flipped_inward) std::swap(tri[1], tri[2]);
    for (std::uint32_t& i : tri) {
      if (remap[i] == UINT32_MAX) {
        remap[i] = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[i]);
      }
      i = remap[i];
    }
    out.triangles.push_back(tri);
  }
  return out;
}

}  // namespace rocklab::geometry
