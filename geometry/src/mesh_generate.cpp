#include "rocklab/geometry/mesh_generate.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <stdexcept>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry {

namespace {

using Tri = std::array<std::uint32_t, 3>;

void orientOutward(TriangleMesh& m) {
  double six_v = 0;
  for (const auto& t : m.triangles) six_v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]]));
  if (six_v < 0)
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
}

Vec3 randomUnit(Rng& rng) {
  const double z = rng.uniform(-1.0, 1.0), phi = rng.uniform(0.0, 2 * std::numbers::pi);
  const double s = std::sqrt(1 - z * z);
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// Radius of the polytope {x : n_k·x <= d_k} along the unit direction u.
double polytopeRadius(const std::vector<std::pair<Vec3, double>>& planes, const Vec3& u) {
  double r = 1e9;
  for (const auto& [n, d] : planes) {
    const double c = n.dot(u);
    if (c > 1e-12) r = std::min(r, d / c);
  }
  return r;
}

}  // namespace

TriangleMesh icosphere(int level, double radius) {
  const double p = (1 + std::sqrt(5.0)) / 2;
  TriangleMesh m;
  m.vertices = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (Vec3& v : m.vertices) v.normalize();
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
      const auto idx = static_cast<std::uint32_t>(m.vertices.size() - 1);
      mid[key] = idx;
      return idx;
    };
    std::vector<Tri> next;
    next.reserve(4 * m.triangles.size());
    for (const Tri& t : m.triangles) {
      const std::uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.push_back({t[0], a, c});
      next.push_back({t[1], b, a});
      next.push_back({t[2], c, b});
      next.push_back({a, b, c});
    }
    m.triangles = std::move(next);
  }
  for (Vec3& v : m.vertices) v *= radius;
  orientOutward(m);
  return m;
}

TriangleMesh boxMesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k)
    m.vertices.emplace_back((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
  // Two triangles per face, outward (checked by the tests through the volume sign).
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},   // z = lo, z = hi
                 {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},   // y = lo, y = hi
                 {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};  // x = lo, x = hi
  return m;
}

TriangleMesh ellipsoidMesh(double a, double b, double c, int level) {
  TriangleMesh m = icosphere(level, 1.0);
  for (Vec3& v : m.vertices) v = Vec3(a * v.x(), b * v.y(), c * v.z());
  return m;
}

ParticleKind parseParticleKind(const std::string& name) {
  if (name == "pebble") return ParticleKind::Pebble;
  if (name == "crushed") return ParticleKind::Crushed;
  if (name == "flake") return ParticleKind::Flake;
  throw std::invalid_argument("particle kind '" + name + "': allowed are pebble, crushed, flake");
}

TriangleMesh generateParticle(ParticleKind kind, std::uint64_t seed, int level) {
  Rng rng(seed * 7919 + static_cast<std::uint64_t>(kind));
  TriangleMesh m = icosphere(level, 1.0);
  if (kind == ParticleKind::Pebble) {
    // Smooth bumps of width w (in 1 − cos of the angle) and a fine roughness.
    struct Bump {
      Vec3 d;
      double a, w;
    };
    std::vector<Bump> bumps;
    for (int k = 0; k < 12; ++k) bumps.push_back({randomUnit(rng), rng.uniform(-0.12, 0.12), rng.uniform(0.15, 0.5)});
    for (int k = 0; k < 60; ++k) bumps.push_back({randomUnit(rng), rng.uniform(-0.012, 0.012), rng.uniform(0.01, 0.03)});
    const Vec3 axes(1.0, rng.uniform(0.75, 0.85), rng.uniform(0.55, 0.68));
    for (Vec3& u : m.vertices) {
      double f = 1.0;
      for (const Bump& b : bumps) f += b.a * std::exp((u.dot(b.d) - 1.0) / b.w);
      // Radius of the ellipsoid along u, times the bump field.
      const double re = 1.0 / std::sqrt(std::pow(u.x() / axes.x(), 2) + std::pow(u.y() / axes.y(), 2) +
                                        std::pow(u.z() / axes.z(), 2));
      u *= re * std::max(f, 0.3);
    }
  } else {
    std::vector<std::pair<Vec3, double>> planes;
    const int count = 10 + static_cast<int>(rng.uniform() * 5);
    for (int k = 0; k < count; ++k) planes.push_back({randomUnit(rng), rng.uniform(0.75, 1.0)});
    // Bound it by a sphere of radius 1.3 too, so that a direction no plane faces stays finite.
    for (Vec3& u : m.vertices) u *= std::min(polytopeRadius(planes, u), 1.3) * (1.0 + rng.uniform(-0.004, 0.004));
    if (kind == ParticleKind::Flake)
      for (Vec3& v : m.vertices) v = Vec3(v.x(), 0.85 * v.y(), 0.3 * v.z());
  }
  orientOutward(m);
  return m;
}

void writeMeshFile(const std::string& path, const TriangleMesh& mesh) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".stl" && ext != ".ply" && ext != ".obj")
    throw std::runtime_error("mesh file '" + path + "': unknown extension '" + ext + "' (allowed: .stl, .ply, .obj)");
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error("cannot write mesh file '" + tmp + "'");
    if (ext == ".stl") {
      char header[80] = "rocklab mesh (binary STL)";
      out.write(header, 80);
      const auto n = static_cast<std::uint32_t>(mesh.triangles.size());
      out.write(reinterpret_cast<const char*>(&n), 4);
      for (const auto& t : mesh.triangles) {
        const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
        Vec3 nrm = (b - a).cross(c - a);
        if (nrm.squaredNorm() > 0) nrm.normalize();
        float f[12];
        for (int k = 0; k < 3; ++k) {
          f[k] = static_cast<float>(nrm[k]);
          f[3 + k] = static_cast<float>(a[k]);
          f[6 + k] = static_cast<float>(b[k]);
          f[9 + k] = static_cast<float>(c[k]);
        }
        out.write(reinterpret_cast<const char*>(f), sizeof f);
        const std::uint16_t attr = 0;
        out.write(reinterpret_cast<const char*>(&attr), 2);
      }
    } else {
      char buf[128];
      if (ext == ".ply")
        out << "ply\nformat ascii 1.0\ncomment rocklab mesh\nelement vertex " << mesh.vertices.size()
            << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << mesh.triangles.size()
            << "\nproperty list uchar int vertex_indices\nend_header\n";
      else
        out << "# rocklab mesh\n";
      for (const Vec3& v : mesh.vertices) {
        std::snprintf(buf, sizeof buf, ext == ".obj" ? "v %.7g %.7g %.7g\n" : "%.7g %.7g %.7g\n", v.x(), v.y(), v.z());
        out << buf;
      }
      for (const auto& t : mesh.triangles) {
        if (ext == ".obj")
          out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
        else
          out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
      }
    }
    if (!out) throw std::runtime_error("cannot write mesh file '" + tmp + "'");
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace rocklab::geometry
