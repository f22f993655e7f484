#include "rocklab/geometry/mesh_voxels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "z_ray_crossing.h"

namespace rocklab::geometry {

namespace {

// Column offsets (fractions of a cell), irrational so no ray meets a mesh edge of
// a grid-aligned shape exactly.
constexpr double kJitterX = 0.0137458;
constexpr double kJitterY = 0.0291735;

// 1-D squared distance transform (lower envelope of parabolas), in place on f[0..n).
void edt1d(std::vector<double>& f, int n, std::vector<double>& d, std::vector<int>& v, std::vector<double>& z) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  int k = 0;
  v[0] = 0;
  z[0] = -inf;
  z[1] = inf;
  for (int q = 1; q < n; ++q) {
    if (f[q] == inf) continue;
    if (f[v[0]] == inf) {  // first finite value
      v[0] = q;
      continue;
    }
    double s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * q - 2.0 * v[k]);
    while (s <= z[k]) {
      --k;
      s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * q - 2.0 * v[k]);
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = inf;
  }
  if (f[v[0]] == inf) return;  // nothing finite: leave as is
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    d[q] = (q - v[k]) * (q - v[k]) + f[v[k]];
  }
  for (int q = 0; q < n; ++q) f[q] = d[q];
}

}  // namespace

std::size_t InsideGrid::insideCount() const {
  std::size_t c = 0;
  for (auto x : inside) c += x;
  return c;
}

InsideGrid voxelizeInside(const TriangleMesh& mesh, int cells_across) {
  if (cells_across < 2) throw std::invalid_argument("voxelizeInside: cells_across must be >= 2");
  const AABB box = mesh.bounds();
  const Vec3 ext = box.hi - box.lo;
  InsideGrid g;
  g.h = ext.maxCoeff() / cells_across;
  if (!(g.h > 0)) throw std::invalid_argument("voxelizeInside: the mesh has no extent");
  for (int a = 0; a < 3; ++a) g.n[a] = static_cast<int>(std::ceil(ext[a] / g.h)) + 2;
  // Cells centred on the box; x and y slightly jittered (see the header).
  const Vec3 span = g.h * Vec3(g.n[0] - 1, g.n[1] - 1, g.n[2] - 1);
  g.origin = 0.5 * (box.lo + box.hi) - 0.5 * span + g.h * Vec3(kJitterX, kJitterY, 0.0);
  g.inside.assign(static_cast<std::size_t>(g.n[0]) * g.n[1] * g.n[2], 0);

  // Crossings of each column: (z, +1 entering / −1 leaving).
  std::vector<std::vector<std::pair<double, int>>> cross(static_cast<std::size_t>(g.n[0]) * g.n[1]);
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const double xlo = std::min({a.x(), b.x(), c.x()}), xhi = std::max({a.x(), b.x(), c.x()});
    const double ylo = std::min({a.y(), b.y(), c.y()}), yhi = std::max({a.y(), b.y(), c.y()});
    const int i0 = std::max(0, static_cast<int>(std::ceil((xlo - g.origin.x()) / g.h)));
    const int i1 = std::min(g.n[0] - 1, static_cast<int>(std::floor((xhi - g.origin.x()) / g.h)));
    const int j0 = std::max(0, static_cast<int>(std::ceil((ylo - g.origin.y()) / g.h)));
    const int j1 = std::min(g.n[1] - 1, static_cast<int>(std::floor((yhi - g.origin.y()) / g.h)));
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j) {
        const auto hit =
            detail::zRayCrossing(a, b, c, g.origin.x() + i * g.h, g.origin.y() + j * g.h);
        if (hit) cross[static_cast<std::size_t>(i) * g.n[1] + j].push_back({hit->z, hit->sign});
      }
  }
  for (int i = 0; i < g.n[0]; ++i)
    for (int j = 0; j < g.n[1]; ++j) {
      auto& cs = cross[static_cast<std::size_t>(i) * g.n[1] + j];
      if (cs.empty()) continue;
      std::sort(cs.begin(), cs.end());
      std::size_t c = 0;
      int winding = 0;
      for (int k = 0; k < g.n[2]; ++k) {
        const double z = g.origin.z() + k * g.h;
        while (c < cs.size() && cs[c].first < z) winding += cs[c++].second;
        g.inside[g.index(i, j, k)] = winding > 0;
      }
    }
  return g;
}

std::vector<bool> pointsInside(const TriangleMesh& mesh, const std::vector<Vec3>& points) {
  std::vector<bool> inside(points.size(), false);
  if (mesh.triangles.empty() || points.empty()) return inside;
  // Triangles binned by their xy bounding boxes on about sqrt(nt) x sqrt(nt) columns.
  const AABB box = mesh.bounds();
  const int bins =
      std::max(1, static_cast<int>(std::sqrt(static_cast<double>(mesh.triangles.size()))));
  const double wx = std::max((box.hi.x() - box.lo.x()) / bins, 1e-300);
  const double wy = std::max((box.hi.y() - box.lo.y()) / bins, 1e-300);
  auto column = [&](double v, double lo, double w) {
    return std::clamp(static_cast<int>(std::floor((v - lo) / w)), 0, bins - 1);
  };
  std::vector<std::vector<std::uint32_t>> bin(static_cast<std::size_t>(bins) * bins);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
    const int i0 = column(std::min({a.x(), b.x(), c.x()}), box.lo.x(), wx);
    const int i1 = column(std::max({a.x(), b.x(), c.x()}), box.lo.x(), wx);
    const int j0 = column(std::min({a.y(), b.y(), c.y()}), box.lo.y(), wy);
    const int j1 = column(std::max({a.y(), b.y(), c.y()}), box.lo.y(), wy);
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j) bin[static_cast<std::size_t>(i) * bins + j].push_back(t);
  }
  for (std::size_t q = 0; q < points.size(); ++q) {
    const Vec3& p = points[q];
    if (box.distance(p) > 0) continue;
    int winding = 0;
    for (std::uint32_t t : bin[static_cast<std::size_t>(column(p.x(), box.lo.x(), wx)) * bins +
                               column(p.y(), box.lo.y(), wy)]) {
      const auto& tri = mesh.triangles[t];
      const auto hit = detail::zRayCrossing(mesh.vertices[tri[0]], mesh.vertices[tri[1]],
                                            mesh.vertices[tri[2]], p.x(), p.y());
      if (hit && hit->z < p.z()) winding += hit->sign;
    }
    inside[q] = winding > 0;
  }
  return inside;
}

void computeDistance(InsideGrid& g) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const std::size_t total = g.inside.size();
  std::vector<double> f2(total);
  for (std::size_t q = 0; q < total; ++q) f2[q] = g.inside[q] ? inf : 0.0;
  const int nmax = std::max({g.n[0], g.n[1], g.n[2]});
  std::vector<double> line(nmax), d(nmax), z(nmax + 1);
  std::vector<int> v(nmax);
  // Pass along each axis in turn.
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int p = 0; p < g.n[a1]; ++p)
      for (int q = 0; q < g.n[a2]; ++q) {
        std::array<int, 3> ijk{};
        ijk[a1] = p;
        ijk[a2] = q;
        for (int s = 0; s < g.n[axis]; ++s) {
          ijk[axis] = s;
          line[s] = f2[g.index(ijk[0], ijk[1], ijk[2])];
        }
        edt1d(line, g.n[axis], d, v, z);
        for (int s = 0; s < g.n[axis]; ++s) {
          ijk[axis] = s;
          f2[g.index(ijk[0], ijk[1], ijk[2])] = line[s];
        }
      }
  }
  g.distance.assign(total, 0.0f);
  for (std::size_t q = 0; q < total; ++q)
    if (g.inside[q]) g.distance[q] = static_cast<float>(std::max(0.0, (std::sqrt(f2[q]) - 0.5) * g.h));
}

}  // namespace rocklab::geometry
