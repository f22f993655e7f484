#pragma once
// Hash grid over spheres for neighbour and overlap queries (random insertion, bond
// pairs, void filling). The cell is at least the largest interaction distance (twice
// the largest radius, plus any gap allowance), so every partner of a query lies in
// one of the 27 neighbour cells. Visits are in a fixed order (cells dz, dy, dx, then
// insertion order), so callers are deterministic; cells whose keys collide are both
// visited, so a caller that collects pairs removes repeats.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry {

struct SphereHashGrid {
  struct Entry {
    Sphere sphere;
    std::size_t id;  // the caller's index (0 when it does not need one)
  };
  double cell;
  std::unordered_map<std::int64_t, std::vector<Entry>> cells;

  static std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  }
  std::array<std::int64_t, 3> index(const Vec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() / cell)),
            static_cast<std::int64_t>(std::floor(p.y() / cell)),
            static_cast<std::int64_t>(std::floor(p.z() / cell))};
  }
  void insert(const Sphere& s, std::size_t id = 0) {
    const auto c = index(s.centre);
    cells[key(c[0], c[1], c[2])].push_back({s, id});
  }
  /// Calls visit(entry) for every sphere in the 27 cells around p until it returns true;
  /// returns whether a visit did. Cells whose keys collide are both visited (harmless).
  template <class Visit>
  bool anyNear(const Vec3& p, Visit&& visit) const {
    const auto c = index(p);
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const auto it = cells.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == cells.end()) continue;
          for (const Entry& e : it->second)
            if (visit(e)) return true;
        }
    return false;
  }
  template <class Visit>
  void forEachNear(const Vec3& p, Visit&& visit) const {
    anyNear(p, [&](const Entry& e) {
      visit(e);
      return false;
    });
  }
  bool overlaps(const Vec3& p, double r) const {
    return anyNear(p, [&](const Entry& e) {
      const double reach = e.sphere.radius + r;
      return (e.sphere.centre - p).squaredNorm() < reach * reach;
    });
  }
};

}  // namespace rocklab::geometry
