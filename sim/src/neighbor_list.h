#pragma once
// Neighbour search: all ball pairs closer than r_i + r_j + skin, found with a
// hierarchy of uniform grids (one level per doubling of the radius), so that a
// 7:1 size ratio costs little more than monodisperse: a ball searches the 27
// cells around it in its own level and in every coarser level; each level's cell
// size is set by its largest ball. Internal to rocklab_sim.
#include <cstdint>
#include <span>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim::detail {

using geometry::Vec3;

/// Pairs in compressed rows: row i lists partners j > i in ascending order. The
/// order is canonical, so sums over it are the same whatever the number of
/// threads and whenever the list was rebuilt.
struct PairList {
  std::vector<std::uint32_t> row_offset;  // [n+1]
  std::vector<std::uint32_t> partner;     // [pairs] j of each pair
  std::size_t size() const { return partner.size(); }
};

class NeighborFinder {
 public:
  /// Rebuilds `out` for the given balls. `threads` as for OpenMP num_threads.
  /// Balls with the same `group` >= 0 (members of one clump) never pair; an empty
  /// `group` means every ball is on its own. Nor do the pairs of `excluded`
  /// (keys i << 32 | j, i < j, ascending: pairs held by contact bonds).
  void build(std::span<const Vec3> position, std::span<const double> radius, double skin,
             int threads, PairList& out, int max_levels = 8,
             std::span<const std::int32_t> group = {},
             std::span<const std::uint64_t> excluded = {});

 private:
  struct Level {
    double cell = 0.0;           // m, edge of a cell
    Vec3 origin = Vec3::Zero();  // m, corner of cell (0,0,0)
    std::int64_t nx = 1, ny = 1, nz = 1;
    std::vector<std::uint32_t> cell_start;  // [cells+1]
    std::vector<std::uint32_t> members;     // ball indices, grouped by cell
  };
  std::vector<Level> levels_;
  std::vector<std::uint8_t> level_of_;
  std::vector<std::vector<std::uint64_t>> thread_keys_;
  std::vector<std::uint64_t> keys_;
};

}  // namespace rocklab::sim::detail
