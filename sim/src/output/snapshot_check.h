#pragma once
// Size check shared by the snapshot writers (run file, VTK series). Internal to
// rocklab_sim; needs neither HDF5 nor VTK.
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "rocklab/sim/snapshot.h"

namespace rocklab::sim::output::detail {

/// Number of particles in a snapshot; throws when a ball array that every
/// frame holds (ROCKLAB_SNAPSHOT_FIELDS: Ball, Always) differs in length from position.
inline std::size_t particleCount(const Snapshot& s) {
  const std::size_t n = s.position.size();
#define ROCKLAB_SIZE(type, name, index, unit, frame, meaning)                                     \
  {SnapshotIndex::index == SnapshotIndex::Ball && FrameWrite::frame == FrameWrite::Always, #name, \
   s.name.size()},
  const std::tuple<bool, const char*, std::size_t> sizes[] = {
      ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_SIZE)};
#undef ROCKLAB_SIZE
  for (const auto& [checked, name, size] : sizes) {
    if (checked && size != n) {
      throw std::invalid_argument("snapshot: " + std::string(name) + " has " +
                                  std::to_string(size) + " entries but position has " +
                                  std::to_string(n));
    }
  }
  return n;
}

/// What is wrong with a snapshot's bond arrays: the array, the row and why.
struct BondProblem {
  const char* array;
  std::size_t row;
  std::string what;
};

/// The first problem of the bond arrays (ROCKLAB_SNAPSHOT_FIELDS: Bond) of a
/// snapshot of `balls` balls, or none: every bond array as long as bond_intact
/// (the row named is that length), ends that are existing, distinct balls,
/// intact 0 or 1.
inline std::optional<BondProblem> bondProblem(const Snapshot& s, std::size_t balls) {
  const std::size_t m = s.bond_intact.size();
#define ROCKLAB_BOND_SIZE(type, name, index, unit, frame, meaning)                          \
  if (SnapshotIndex::index == SnapshotIndex::Bond && s.name.size() != m)                   \
    return BondProblem{#name, s.name.size(),                                                \
                       "has " + std::to_string(s.name.size()) + " rows but bond_intact has " + \
                           std::to_string(m)};
  ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_BOND_SIZE)
#undef ROCKLAB_BOND_SIZE
  for (std::size_t k = 0; k < m; ++k) {
    for (const auto& [name, end] : {std::pair{"bond_a", s.bond_a[k]}, std::pair{"bond_b", s.bond_b[k]}})
      if (end >= balls)
        return BondProblem{name, k, "ball " + std::to_string(end) + " does not exist (the frame has " +
                                        std::to_string(balls) + " balls)"};
    if (s.bond_a[k] == s.bond_b[k])
      return BondProblem{"bond_b", k, "joins ball " + std::to_string(s.bond_a[k]) + " to itself"};
    if (s.bond_intact[k] > 1)
      return BondProblem{"bond_intact", k, "value " + std::to_string(s.bond_intact[k]) + " (allowed: 0, 1)"};
  }
  return std::nullopt;
}

}  // namespace rocklab::sim::output::detail
