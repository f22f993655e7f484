#include "rocklab/geometry/mesh_to_clump.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <stdexcept>

#include "rocklab/geometry/clump_shape.h"
#include "rocklab/geometry/mesh_properties.h"
#include "rocklab/geometry/mesh_voxels.h"

namespace rocklab::geometry {

namespace {

// Evenly thinned to at most `cap` (keeps the spatial spread of the nodes).
template <class T>
std::vector<T> thin(const std::vector<T>& in, std::size_t cap) {
  if (in.size() <= cap) return in;
  std::vector<T> out;
  out.reserve(cap);
  const double stride = static_cast<double>(in.size()) / static_cast<double>(cap);
  for (std::size_t k = 0; k < cap; ++k) out.push_back(in[static_cast<std::size_t>(k * stride)]);
  return out;
}

std::vector<Sphere> surfaceCandidates(const TriangleMesh& mesh, const MeshToClumpOptions& o, double d_eq) {
  // Nodes: vertices (area-weighted normals) + random surface points (face normals).
  std::vector<Vec3> vnormal(mesh.vertices.size(), Vec3::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (auto i : t) vnormal[i] += n;
  }
  std::vector<SurfacePoint> nodes;
  nodes.reserve(mesh.vertices.size() + o.surface_samples);
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (vnormal[i].squaredNorm() > 0) nodes.push_back({mesh.vertices[i], vnormal[i].normalized()});
  for (const auto& s : sampleSurface(mesh, o.surface_samples, o.seed)) nodes.push_back(s);
  const std::vector<SurfacePoint> sites = thin(nodes, static_cast<std::size_t>(o.max_candidates));
  const double t = o.touch_tolerance * d_eq, r_min = o.min_radius * d_eq;
  std::vector<Sphere> out;
  for (const SurfacePoint& s : sites) {
    const Vec3 n = -s.normal;  // inward
    double r = std::numeric_limits<double>::infinity();
    for (const SurfacePoint& p : nodes) {
      const Vec3 d = p.point - s.point;
      const double dn = d.dot(n);
      if (dn <= t) continue;
      r = std::min(r, (d.squaredNorm() - t * t) / (2.0 * (dn - t)));
    }
    if (!std::isfinite(r)) continue;
    // The tolerance fixed where the centre goes; the radius is what fits there: the
    // distance to the nearest node, so the sphere does not poke through the surface.
    const Vec3 c = s.point + r * n;
    double fit = r;
    for (const SurfacePoint& p : nodes) fit = std::min(fit, (p.point - c).norm());
    if (fit >= r_min && fit > 0) out.push_back({c, fit});
  }
  return out;
}

// Moves a ball centre up the gradient of the distance to the surface (away from its
// closest point) by at most `reach`, and gives it that exact distance as radius.
// Within `reach` of the start the distance is at most r0 + reach, so only triangles
// whose bounding box comes within r0 + 2 reach of the start can be closest: the
// iterations search those (tens of triangles of an 80k-triangle scan, not all).
Sphere refineBall(const TriangleMesh& mesh, Vec3 c, double reach) {
  Vec3 q = mesh.closestPoint(c);
  double r = (c - q).norm();
  TriangleMesh near;
  near.vertices = mesh.vertices;
  for (const auto& t : mesh.triangles) {
    AABB box;
    for (auto i : t) box.extend(mesh.vertices[i]);
    if (box.distance(c) <= r + 2 * reach) near.triangles.push_back(t);
  }
  const Vec3 start = c;
  double step = 0.25 * reach;
  for (int it = 0; it < 40 && step > 1e-4 * reach; ++it) {
    if (!(r > 0)) break;
    const Vec3 trial = c + step * (c - q) / r;
    if ((trial - start).norm() > reach) {
      step *= 0.5;
      continue;
    }
    const Vec3 tq = near.closestPoint(trial);
    const double tr = (trial - tq).norm();
    if (tr > r) {
      c = trial;
      q = tq;
      r = tr;
    } else {
      step *= 0.5;
    }
  }
  return {c, r};
}

// Ridge cells of the distance transform: the distance rises by less than kMedialSlope
// per unit step towards every neighbour. Off the medial axis it rises at slope 1 towards
// the axis; on it (a ridge, a sheet or the centre) it cannot. 0.5 leaves the grid's
// ± h/2 noise room (a centre of maximal balls criterion, relaxed for the grid).
constexpr double kMedialSlope = 0.5;

std::vector<Sphere> medialCandidates(InsideGrid& g, const MeshToClumpOptions& o, double d_eq) {
  computeDistance(g);
  std::vector<Sphere> out;
  for (int i = 1; i + 1 < g.n[0]; ++i)
    for (int j = 1; j + 1 < g.n[1]; ++j)
      for (int k = 1; k + 1 < g.n[2]; ++k) {
        const double d = g.distance[g.index(i, j, k)];
        if (d <= 0 || d < o.min_radius * d_eq) continue;
        bool ridge = true;
        for (int a = -1; a <= 1 && ridge; ++a)
          for (int b = -1; b <= 1 && ridge; ++b)
            for (int c = -1; c <= 1; ++c) {
              const double step = g.h * std::sqrt(static_cast<double>(a * a + b * b + c * c));
              if (g.distance[g.index(i + a, j + b, k + c)] - d > kMedialSlope * step) {
                ridge = false;
                break;
              }
            }
        if (ridge) out.push_back({g.centre(i, j, k), d});
      }
  return thin(out, static_cast<std::size_t>(o.max_candidates));
}

// Inside cells within the sphere not yet covered; marks them when `mark`.
std::size_t coverage(const InsideGrid& g, std::vector<std::uint8_t>& covered, const Sphere& s, bool mark) {
  const Vec3 rel = (s.centre - g.origin) / g.h;
  const double r = s.radius / g.h;
  std::size_t gain = 0;
  const int i0 = std::max(0, static_cast<int>(std::ceil(rel.x() - r)));
  const int i1 = std::min(g.n[0] - 1, static_cast<int>(std::floor(rel.x() + r)));
  for (int i = i0; i <= i1; ++i) {
    const double dx = i - rel.x();
    const double ry2 = r * r - dx * dx;
    if (ry2 < 0) continue;
    const double ry = std::sqrt(ry2);
    const int j0 = std::max(0, static_cast<int>(std::ceil(rel.y() - ry)));
    const int j1 = std::min(g.n[1] - 1, static_cast<int>(std::floor(rel.y() + ry)));
    for (int j = j0; j <= j1; ++j) {
      const double dy = j - rel.y();
      const double rz2 = ry2 - dy * dy;
      if (rz2 < 0) continue;
      const double rz = std::sqrt(rz2);
      const int k0 = std::max(0, static_cast<int>(std::ceil(rel.z() - rz)));
      const int k1 = std::min(g.n[2] - 1, static_cast<int>(std::floor(rel.z() + rz)));
      for (int k = k0; k <= k1; ++k) {
        const std::size_t q = g.index(i, j, k);
        if (g.inside[q] && !covered[q]) {
          ++gain;
          if (mark) covered[q] = 1;
        }
      }
    }
  }
  return gain;
}

}  // namespace

std::vector<SurfacePoint> sampleSurface(const TriangleMesh& mesh, int count, std::uint64_t seed) {
  std::vector<double> cumulative;
  cumulative.reserve(mesh.triangles.size());
  double total = 0;
  for (const auto& t : mesh.triangles) {
    total += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]).norm();
    cumulative.push_back(total);
  }
  std::vector<SurfacePoint> out;
  if (!(total > 0) || count <= 0) return out;
  Rng rng(seed);
  out.reserve(static_cast<std::size_t>(count));
  for (int s = 0; s < count; ++s) {
    const double u = rng.uniform() * total;
    const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), u);
    const auto& t = mesh.triangles[std::min<std::size_t>(it - cumulative.begin(), mesh.triangles.size() - 1)];
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    // Uniform point in a triangle: (1 − √u1) a + √u1 (1 − u2) b + √u1 u2 c.
    const double su = std::sqrt(rng.uniform()), v = rng.uniform();
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.squaredNorm() > 0)) continue;
    out.push_back({(1 - su) * a + su * (1 - v) * b + su * v * c, n.normalized()});
  }
  return out;
}

ClumpResult meshToClumpWithStop(const TriangleMesh& mesh, const MeshToClumpOptions& o) {
  if (o.max_spheres < 1) throw std::invalid_argument("meshToClump: max_spheres must be >= 1");
  if (!(o.volume_tolerance >= 0 && o.volume_tolerance < 1))
    throw std::invalid_argument("meshToClump: volume_tolerance must be in [0, 1)");
  if (o.grid_cells < 8 || o.grid_cells > 512) throw std::invalid_argument("meshToClump: grid_cells must be in [8, 512]");
  if (o.min_radius < 0 || o.touch_tolerance < 0) throw std::invalid_argument("meshToClump: radii must be >= 0");
  InsideGrid g = voxelizeInside(mesh, o.grid_cells);
  const std::size_t inside_total = g.insideCount();
  if (inside_total == 0) throw std::runtime_error("meshToClump: no grid cell lies inside the mesh (is it closed?)");

  const double d_eq = std::cbrt(6.0 * static_cast<double>(inside_total) / std::numbers::pi) * g.h;
  const bool medial = o.method == ClumpMethod::MedialAxis;
  const std::vector<Sphere> cand = medial ? medialCandidates(g, o, d_eq) : surfaceCandidates(mesh, o, d_eq);
  if (cand.empty())
    throw std::runtime_error("meshToClump: no candidate sphere has a radius >= min_radius (" +
                             std::to_string(o.min_radius) + " of the equivalent diameter); lower it");
  // A chosen ball refined on the exact distance to the mesh: the grid places a medial
  // ball to ± h/2, the touch tolerance a surface sphere's centre to within t.
  const double refine_step = medial ? g.h : std::max(o.touch_tolerance * d_eq, 1e-3 * d_eq);
  // The true uncovered fraction 1 − V_union / V_mesh of the refined spheres: what the
  // tolerance means and what `rocklab shape` reports (volume_error). The voxel count
  // only says when it is worth computing: it misses up to a few % (cells cut by the
  // surface, refinement), so a stop on it alone ends above the tolerance.
  const double mesh_volume = meshMassProperties(mesh).volume;
  auto trueUncovered = [&](const std::vector<Sphere>& refined) {
    return 1.0 - clumpMassProperties(refined, 1.0, ClumpMassDistribution::Union).union_volume / mesh_volume;
  };

  // Lazy greedy maximum coverage.
  std::vector<std::uint8_t> covered(g.inside.size(), 0);
  std::priority_queue<std::pair<std::size_t, std::size_t>> queue;  // (gain bound, candidate), largest first
  for (std::size_t c = 0; c < cand.size(); ++c) queue.push({coverage(g, covered, cand[c], false), c});
  ClumpResult result;
  result.stop = ClumpStop::Spheres;
  std::size_t uncovered = inside_total;
  const bool tolerance = o.volume_tolerance > 0;
  std::size_t checked = 0;  // spheres when the true fraction was last computed
  while (true) {
    if (tolerance && result.spheres.size() > checked &&
        static_cast<double>(uncovered) <= o.volume_tolerance * static_cast<double>(inside_total)) {
      checked = result.spheres.size();
      result.uncovered = trueUncovered(result.spheres);
      if (result.uncovered <= o.volume_tolerance) {
        result.stop = ClumpStop::Tolerance;
        return result;
      }
    }
    if (static_cast<int>(result.spheres.size()) >= o.max_spheres) {
      result.stop = ClumpStop::Spheres;
      break;
    }
    if (uncovered == 0) {
      result.stop = ClumpStop::Covered;
      break;
    }
    if (queue.empty()) {
      result.stop = ClumpStop::Exhausted;
      break;
    }
    auto [bound, c] = queue.top();
    queue.pop();
    const std::size_t gain = coverage(g, covered, cand[c], false);
    if (gain == 0) continue;
    if (!queue.empty() && gain < queue.top().first) {
      queue.push({gain, c});  // stale: re-queue with its true gain
      continue;
    }
    uncovered -= coverage(g, covered, cand[c], true);
    result.spheres.push_back(refineBall(mesh, cand[c].centre, refine_step));
  }
  result.uncovered = trueUncovered(result.spheres);
  return result;
}

std::vector<Sphere> meshToClump(const TriangleMesh& mesh, const MeshToClumpOptions& o) {
  return meshToClumpWithStop(mesh, o).spheres;
}

const char* clumpStopReason(ClumpStop stop) {
  switch (stop) {
    case ClumpStop::Spheres: return "sphere count reached (--spheres)";
    case ClumpStop::Tolerance: return "tolerance reached (--tolerance)";
    case ClumpStop::Covered: return "every inside grid cell covered: more spheres add no volume";
    case ClumpStop::Exhausted:
      return "no candidate sphere adds volume (the rest of the inside is thinner than --min-radius allows, or "
             "finer than --grid resolves)";
  }
  return "";
}

ClumpFitError clumpFitError(const MeshMassProperties& mesh_props, const std::vector<Sphere>& spheres,
                            const std::vector<SurfacePoint>& samples, int resolution) {
  if (spheres.empty()) throw std::invalid_argument("clumpFitError: no spheres");
  const double density = mesh_props.mass / mesh_props.volume;
  const ClumpMassProperties u = clumpMassProperties(spheres, density, ClumpMassDistribution::Union, 0.0, resolution);
  ClumpFitError e;
  e.spheres = spheres.size();
  e.union_volume = u.union_volume;
  e.volume_error = (u.union_volume - mesh_props.volume) / mesh_props.volume;
  const double scale = mesh_props.volume / u.union_volume;
  for (int a = 0; a < 3; ++a) {
    const double im = mesh_props.principal_moments[a];
    e.inertia_error = std::max(e.inertia_error, std::abs(u.principal_moments[a] - im) / im);
    e.inertia_error_mass_scaled = std::max(e.inertia_error_mass_scaled, std::abs(scale * u.principal_moments[a] - im) / im);
  }
  double sum = 0;
  for (const SurfacePoint& p : samples) {
    double sd = std::numeric_limits<double>::infinity();
    for (const Sphere& s : spheres) sd = std::min(sd, (p.point - s.centre).norm() - s.radius);
    sum += std::abs(sd);
    e.surface_error_max = std::max(e.surface_error_max, std::abs(sd));
  }
  e.surface_error_mean = samples.empty() ? 0 : sum / static_cast<double>(samples.size());
  return e;
}

}  // namespace rocklab::geometry
