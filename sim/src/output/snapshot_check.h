#pragma once
// Size check shared by the snapshot writers (run file, VTK series). Internal to
// rocklab_sim; needs neither HDF5 nor VTK.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <tuple>

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

}  // namespace rocklab::sim::output::detail
