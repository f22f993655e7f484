#include "rocklab/geometry/packing.h"

#include <cmath>
#include <unordered_map>

namespace rocklab::geometry {

std::vector<Vec3> latticePoints(LatticeKind kind, double cell, const Vec3& offset, const Vec3& corner,
                                const std::array<int, 3>& counts) {
  std::vector<Vec3> basis{Vec3(0, 0, 0)};
  if (kind == LatticeKind::BodyCentred) basis.emplace_back(0.5, 0.5, 0.5);
  if (kind == LatticeKind::FaceCentred) {
    basis.emplace_back(0.5, 0.5, 0.0);
    basis.emplace_back(0.5, 0.0, 0.5);
    basis.emplace_back(0.0, 0.5, 0.5);
  }
  std::vector<Vec3> points;
  points.reserve(basis.size() * counts[0] * counts[1] * counts[2]);
  // z outermost, so that index order is layer by layer like LIGGGHTS create_atoms.
  // Rounded as LAMMPS' Lattice::lattice2box does, (i + b) a + a origin, so that
  // lattices whose neighbours touch "to within rounding" touch in the same places.
  const Vec3 shift = offset * cell;
  for (int k = 0; k < counts[2]; ++k)
    for (int j = 0; j < counts[1]; ++j)
      for (int i = 0; i < counts[0]; ++i)
        for (const Vec3& b : basis) points.push_back(((Vec3(i, j, k) + b) * cell + shift) + corner);
  return points;
}

std::uint64_t Rng::next() {
  std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double Rng::uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

namespace {
// Hash grid over placed spheres for overlap queries.
struct HashGrid {
  double cell;
  std::unordered_map<std::int64_t, std::vector<Sphere>> cells;
  static std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  }
  std::array<std::int64_t, 3> index(const Vec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() / cell)),
            static_cast<std::int64_t>(std::floor(p.y() / cell)),
            static_cast<std::int64_t>(std::floor(p.z() / cell))};
  }
  void insert(const Sphere& s) {
    const auto c = index(s.centre);
    cells[key(c[0], c[1], c[2])].push_back(s);
  }
  bool overlaps(const Vec3& p, double r) const {
    const auto c = index(p);
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const auto it = cells.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == cells.end()) continue;
          for (const Sphere& s : it->second)
            if ((s.centre - p).squaredNorm() < (s.radius + r) * (s.radius + r)) return true;
        }
    return false;
  }
};
}  // namespace

std::vector<Vec3> randomNonOverlapping(const std::vector<double>& radii, const Vec3& lo, const Vec3& hi,
                                       const std::vector<Sphere>& existing, Rng& rng, int max_attempts) {
  double r_max = 0;
  for (double r : radii) r_max = std::max(r_max, r);
  for (const Sphere& s : existing) r_max = std::max(r_max, s.radius);
  HashGrid grid{2.0 * r_max, {}};
  // Spheres larger than a cell would be missed by the 27-cell query: the cell is
  // set by the largest radius, so every overlap partner is in a neighbour cell.
  for (const Sphere& s : existing) grid.insert(s);
  std::vector<Vec3> placed;
  placed.reserve(radii.size());
  for (double r : radii) {
    bool ok = false;
    for (int attempt = 0; attempt < max_attempts && !ok; ++attempt) {
      const Vec3 p(rng.uniform(lo.x() + r, hi.x() - r), rng.uniform(lo.y() + r, hi.y() - r),
                   rng.uniform(lo.z() + r, hi.z() - r));
      if (grid.overlaps(p, r)) continue;
      grid.insert({p, r});
      placed.push_back(p);
      ok = true;
    }
    if (!ok) break;
  }
  return placed;
}

}  // namespace rocklab::geometry
