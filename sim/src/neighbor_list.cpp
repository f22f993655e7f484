#include "neighbor_list.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace rocklab::sim::detail {

namespace {
constexpr int kMaxLevels = 8;
// Cells per level are capped at this multiple of its ball count: a ball that
// flew far away enlarges the cells instead of exhausting memory.
constexpr double kMaxCellsPerBall = 8.0;
}  // namespace

void NeighborFinder::build(std::span<const Vec3> position, std::span<const double> radius,
                           double skin, int threads, PairList& out, int max_levels,
                           std::span<const std::int32_t> group,
                           std::span<const std::uint64_t> excluded) {
  const std::size_t n = position.size();
  out.row_offset.assign(n + 1, 0);
  out.partner.clear();
  if (n < 2) return;

  // Levels: level k holds radii in [r_min 2^k, r_min 2^(k+1)).
  const double r_min = *std::min_element(radius.begin(), radius.end());
  level_of_.resize(n);
  int level_count = 1;
  for (std::size_t i = 0; i < n; ++i) {
    const int top = std::clamp(max_levels, 1, kMaxLevels) - 1;
    const int k = std::min(top, static_cast<int>(std::floor(std::log2(radius[i] / r_min))));
    level_of_[i] = static_cast<std::uint8_t>(k);
    level_count = std::max(level_count, k + 1);
  }
  levels_.assign(level_count, Level{});
  std::vector<double> r_max(level_count, 0.0);
  std::vector<std::size_t> count(level_count, 0);
  std::vector<Vec3> lo(level_count, Vec3::Constant(1e300)), hi(level_count, Vec3::Constant(-1e300));
  for (std::size_t i = 0; i < n; ++i) {
    const int k = level_of_[i];
    r_max[k] = std::max(r_max[k], radius[i]);
    ++count[k];
    lo[k] = lo[k].cwiseMin(position[i]);
    hi[k] = hi[k].cwiseMax(position[i]);
  }
  for (int k = 0; k < level_count; ++k) {
    Level& L = levels_[k];
    if (count[k] == 0) continue;
    // A cell must hold every partner within r_k,max + r_other + skin of a ball of
    // this or a finer level: 2 r_k,max + skin covers that with a 27-cell stencil.
    L.cell = 2.0 * r_max[k] + skin;
    const Vec3 extent = hi[k] - lo[k];
    const double max_cells = std::max(27.0, kMaxCellsPerBall * static_cast<double>(count[k]));
    while ((std::floor(extent.x() / L.cell) + 1) * (std::floor(extent.y() / L.cell) + 1) *
               (std::floor(extent.z() / L.cell) + 1) > max_cells)
      L.cell *= 1.5;
    L.origin = lo[k];
    L.nx = static_cast<std::int64_t>(extent.x() / L.cell) + 1;
    L.ny = static_cast<std::int64_t>(extent.y() / L.cell) + 1;
    L.nz = static_cast<std::int64_t>(extent.z() / L.cell) + 1;
    L.cell_start.assign(static_cast<std::size_t>(L.nx * L.ny * L.nz) + 1, 0);
  }
  // Counting sort of balls into the cells of their level (ascending index per cell).
  auto cellOf = [](const Level& L, const Vec3& x, std::int64_t& cx, std::int64_t& cy,
                   std::int64_t& cz) {
    cx = static_cast<std::int64_t>(std::floor((x.x() - L.origin.x()) / L.cell));
    cy = static_cast<std::int64_t>(std::floor((x.y() - L.origin.y()) / L.cell));
    cz = static_cast<std::int64_t>(std::floor((x.z() - L.origin.z()) / L.cell));
  };
  std::vector<std::uint32_t> cell_of_ball(n);
  for (std::size_t i = 0; i < n; ++i) {
    Level& L = levels_[level_of_[i]];
    std::int64_t cx, cy, cz;
    cellOf(L, position[i], cx, cy, cz);
    cx = std::clamp<std::int64_t>(cx, 0, L.nx - 1);
    cy = std::clamp<std::int64_t>(cy, 0, L.ny - 1);
    cz = std::clamp<std::int64_t>(cz, 0, L.nz - 1);
    cell_of_ball[i] = static_cast<std::uint32_t>((cz * L.ny + cy) * L.nx + cx);
    ++L.cell_start[cell_of_ball[i] + 1];
  }
  for (auto& L : levels_) {
    for (std::size_t c = 1; c < L.cell_start.size(); ++c) L.cell_start[c] += L.cell_start[c - 1];
    L.members.resize(L.cell_start.empty() ? 0 : L.cell_start.back());
  }
  {
    std::vector<std::vector<std::uint32_t>> fill(level_count);
    for (int k = 0; k < level_count; ++k)
      fill[k].assign(levels_[k].cell_start.begin(), levels_[k].cell_start.end());
    for (std::size_t i = 0; i < n; ++i)
      levels_[level_of_[i]].members[fill[level_of_[i]][cell_of_ball[i]]++] =
          static_cast<std::uint32_t>(i);
  }

  // Candidate pairs: each ball searches its own level (keeping j > i) and every
  // coarser level (each cross-level pair is found once, by its smaller ball).
  // One thread writes straight into keys_: a second buffer of 8 bytes a pair
  // would be kept for the whole run only to be copied once.
  const int nthreads = std::max(1, threads);
  if (nthreads == 1)
    thread_keys_.clear();
  else
    thread_keys_.resize(nthreads);
#pragma omp parallel num_threads(nthreads)
  {
    auto& keys = nthreads == 1 ? keys_ : thread_keys_[omp_get_thread_num()];
    keys.clear();
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 xi = position[i];
      const double ri = radius[i];
      for (int k = level_of_[i]; k < level_count; ++k) {
        const Level& L = levels_[k];
        if (L.members.empty()) continue;
        const bool same = (k == level_of_[i]);
        std::int64_t cx, cy, cz;
        cellOf(L, xi, cx, cy, cz);
        const std::int64_t x0 = std::max<std::int64_t>(cx - 1, 0), x1 = std::min(cx + 1, L.nx - 1);
        const std::int64_t y0 = std::max<std::int64_t>(cy - 1, 0), y1 = std::min(cy + 1, L.ny - 1);
        const std::int64_t z0 = std::max<std::int64_t>(cz - 1, 0), z1 = std::min(cz + 1, L.nz - 1);
        for (std::int64_t z = z0; z <= z1; ++z)
          for (std::int64_t y = y0; y <= y1; ++y)
            for (std::int64_t x = x0; x <= x1; ++x) {
              const std::size_t c = static_cast<std::size_t>((z * L.ny + y) * L.nx + x);
              for (std::uint32_t m = L.cell_start[c]; m < L.cell_start[c + 1]; ++m) {
                const std::uint32_t j = L.members[m];
                if (same && j <= i) continue;
                const double cut = ri + radius[j] + skin;
                if ((position[j] - xi).squaredNorm() >= cut * cut) continue;
                if (!group.empty() && group[i] >= 0 && group[i] == group[j]) continue;
                const std::uint64_t a = std::min<std::uint64_t>(i, j), b = std::max<std::uint64_t>(i, j);
                keys.push_back((a << 32) | b);
              }
            }
      }
    }
  }
  if (nthreads > 1) {
    keys_.clear();
    for (auto& k : thread_keys_) keys_.insert(keys_.end(), k.begin(), k.end());
  }
  std::sort(keys_.begin(), keys_.end());
  if (!excluded.empty()) {
    // Both ascending: one merge pass drops the excluded pairs.
    std::size_t kept = 0, e = 0;
    for (const std::uint64_t key : keys_) {
      while (e < excluded.size() && excluded[e] < key) ++e;
      if (e < excluded.size() && excluded[e] == key) continue;
      keys_[kept++] = key;
    }
    keys_.resize(kept);
  }

  // Rows by i (keys are sorted by (i, j)).
  out.partner.resize(keys_.size());
  for (std::size_t p = 0; p < keys_.size(); ++p) {
    out.partner[p] = static_cast<std::uint32_t>(keys_[p] & 0xffffffffu);
    ++out.row_offset[(keys_[p] >> 32) + 1];
  }
  for (std::size_t i = 0; i < n; ++i) out.row_offset[i + 1] += out.row_offset[i];
}

}  // namespace rocklab::sim::detail
