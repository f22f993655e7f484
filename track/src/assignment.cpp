#include "rocklab/track/assignment.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <numeric>

namespace rocklab::track {

namespace {

// Hungarian algorithm for n ≤ m (rows ≤ columns), 1-based as in the classic
// shortest-augmenting-path form. Row potentials u, column potentials v keep
// a[i][j] − u[i] − v[j] ≥ 0, with equality on the matching. Row i is added by a
// Dijkstra-like search over columns (minv = least reduced cost to reach a column,
// way = the column it came from) until a free column is reached, then the matching
// is flipped along the path. O(n² m).
std::vector<int> hungarian(const std::vector<double>& a, int n, int m) {
  const double inf = std::numeric_limits<double>::infinity();
  auto cost = [&](int i, int j) { return a[static_cast<std::size_t>(i - 1) * m + (j - 1)]; };
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);  // p[j]: row matched to column j (0 = none)
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double reduced = cost(i0, j) - u[i0] - v[j];
        if (reduced < minv[j]) minv[j] = reduced, way[j] = j0;
        if (minv[j] < delta) delta = minv[j], j1 = j;
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    // Flip the matching along the augmenting path.
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> rowToCol(n, -1);
  for (int j = 1; j <= m; ++j)
    if (p[j] != 0) rowToCol[p[j] - 1] = j - 1;
  return rowToCol;
}

}  // namespace

std::vector<int> solveAssignment(const std::vector<double>& cost, int rows, int cols) {
  assert(rows >= 0 && cols >= 0 && cost.size() == static_cast<std::size_t>(rows) * cols);
  if (rows == 0 || cols == 0) return std::vector<int>(rows, -1);
  if (rows <= cols) return hungarian(cost, rows, cols);
  // More rows than columns: solve the transpose, then invert the matching.
  std::vector<double> transposed(cost.size());
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) transposed[static_cast<std::size_t>(j) * rows + i] = cost[static_cast<std::size_t>(i) * cols + j];
  const std::vector<int> colToRow = hungarian(transposed, cols, rows);
  std::vector<int> rowToCol(rows, -1);
  for (int j = 0; j < cols; ++j) rowToCol[colToRow[j]] = j;
  return rowToCol;
}

std::vector<int> greedyAssignment(const std::vector<double>& cost, int rows, int cols, double max_cost) {
  assert(rows >= 0 && cols >= 0 && cost.size() == static_cast<std::size_t>(rows) * cols);
  std::vector<std::size_t> order(cost.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return cost[x] < cost[y]; });
  std::vector<int> rowToCol(rows, -1);
  std::vector<char> colUsed(cols, 0);
  for (const std::size_t k : order) {
    if (!(cost[k] <= max_cost)) break;
    const int i = static_cast<int>(k / cols), j = static_cast<int>(k % cols);
    if (rowToCol[i] >= 0 || colUsed[j]) continue;
    rowToCol[i] = j;
    colUsed[j] = 1;
  }
  return rowToCol;
}

}  // namespace rocklab::track
