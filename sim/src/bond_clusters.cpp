// Fragments of a bonded body (bonds.h: bondedClusters): union-find over the
// intact bonds.
#include <numeric>
#include <stdexcept>

#include "rocklab/sim/bonds.h"

namespace rocklab::sim {

std::vector<std::uint32_t> bondedClusters(std::size_t ball_count, const BondState& bonds) {
  return bondedClusters(ball_count, bonds.a, bonds.b, bonds.intact);
}

std::vector<std::uint32_t> bondedClusters(std::size_t ball_count, std::span<const std::uint32_t> a,
                                          std::span<const std::uint32_t> b,
                                          std::span<const std::uint8_t> intact) {
  if (a.size() != intact.size() || b.size() != intact.size())
    throw std::invalid_argument("bondedClusters: " + std::to_string(a.size()) + " and " +
                                std::to_string(b.size()) + " bond ends for " +
                                std::to_string(intact.size()) + " bonds");
  std::vector<std::uint32_t> parent(ball_count);
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];  // path halving
    return i;
  };
  for (std::size_t k = 0; k < intact.size(); ++k) {
    if (!intact[k]) continue;
    if (a[k] >= ball_count || b[k] >= ball_count)
      throw std::invalid_argument("bondedClusters: bond " + std::to_string(k) +
                                  " refers to a missing ball");
    const std::uint32_t ra = root(a[k]), rb = root(b[k]);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);  // the lower index is the root
  }
  std::vector<std::uint32_t> label(ball_count, 0);
  std::vector<std::uint32_t> label_of_root(ball_count, UINT32_MAX);
  std::uint32_t next = 0;
  for (std::uint32_t i = 0; i < ball_count; ++i) {
    const std::uint32_t r = root(i);
    if (label_of_root[r] == UINT32_MAX) label_of_root[r] = next++;
    label[i] = label_of_root[r];
  }
  return label;
}

}  // namespace rocklab::sim
