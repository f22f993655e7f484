#pragma once
// Hash grid over placed spheres for overlap queries during random insertion.
// The cell is twice the largest radius, so every overlap partner of a query lies
// in one of the 27 neighbour cells. Internal to rocklab_geometry.
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry::detail {

struct SphereHashGrid {
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

}  // namespace rocklab::geometry::detail
