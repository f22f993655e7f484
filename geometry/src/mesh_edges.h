#pragma once
// The edges of a triangle list, each use by a triangle, sorted so that the uses of one
// undirected edge stand together: the closedness check (mesh_check.cpp) and the hole
// filler (hole_fill.cpp) read the same list.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace rocklab::geometry::detail {

// One use of an undirected edge by a triangle; `forward` when the triangle runs
// lo → hi along it.
struct EdgeUse {
  std::uint64_t key;  // lo << 32 | hi
  std::uint32_t triangle;
  bool forward;
};

inline std::vector<EdgeUse> edgeUses(const std::vector<std::array<std::uint32_t, 3>>& tris) {
  std::vector<EdgeUse> uses;
  uses.reserve(3 * tris.size());
  for (std::uint32_t t = 0; t < tris.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = tris[t][e], b = tris[t][(e + 1) % 3];
      const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
      uses.push_back({(std::uint64_t{lo} << 32) | hi, t, a == lo});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });
  return uses;
}

}  // namespace rocklab::geometry::detail
