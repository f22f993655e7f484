#pragma once
// Sphere placements: regular lattices and seeded random non-overlapping insertion.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::geometry {

enum class LatticeKind { SimpleCubic, BodyCentred, FaceCentred };

/// Points (cell_index + basis) * cell + offset * cell + corner for every cell in
/// [0, counts) — the convention of LAMMPS/LIGGGHTS `lattice ... origin offset`.
std::vector<Vec3> latticePoints(LatticeKind kind, double cell, const Vec3& offset, const Vec3& corner,
                                const std::array<int, 3>& counts);

/// Deterministic 64-bit generator (splitmix64) with its own uniform mapping, so
/// a seed gives the same spheres with any standard library.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  double uniform();                                 // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

 private:
  std::uint64_t state_;
};

struct Sphere {
  Vec3 centre;
  double radius;
};

/// Places `radii.size()` spheres at random in the box [lo, hi] (centres kept a
/// radius inside), none overlapping each other or `existing`. Returns fewer
/// centres when `max_attempts` per sphere run out.
std::vector<Vec3> randomNonOverlapping(const std::vector<double>& radii, const Vec3& lo, const Vec3& hi,
                                       const std::vector<Sphere>& existing, Rng& rng,
                                       int max_attempts = 1000);

}  // namespace rocklab::geometry
