#include "rocklab/geometry/packing.h"

#include <cmath>
#include <unordered_map>

#include "rocklab/geometry/mix64.h"
#include "rocklab/geometry/sphere_hash_grid.h"

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

std::uint64_t Rng::next() { return mix64(state_ += kSplitmixGamma); }

double Rng::uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

std::vector<Vec3> randomNonOverlapping(const std::vector<double>& radii, const Vec3& lo, const Vec3& hi,
                                       const std::vector<Sphere>& existing, Rng& rng, int max_attempts) {
  double r_max = 0;
  for (double r : radii) r_max = std::max(r_max, r);
  for (const Sphere& s : existing) r_max = std::max(r_max, s.radius);
  SphereHashGrid grid{2.0 * r_max, {}};
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
