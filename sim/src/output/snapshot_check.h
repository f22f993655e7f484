#pragma once
// Size check shared by the snapshot writers (run file, VTK series). Internal to
// rocklab_sim; needs neither HDF5 nor VTK.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

#include "rocklab/sim/snapshot.h"

namespace rocklab::sim::output::detail {

/// Number of particles in a snapshot; throws when its arrays differ in length.
inline std::size_t particleCount(const Snapshot& s) {
  const std::size_t n = s.position.size();
  const std::pair<const char*, std::size_t> sizes[] = {{"velocity", s.velocity.size()},
                                                       {"omega", s.omega.size()},
                                                       {"force", s.force.size()},
                                                       {"radius", s.radius.size()},
                                                       {"id", s.id.size()}};
  for (const auto& [name, size] : sizes) {
    if (size != n) {
      throw std::invalid_argument("snapshot: " + std::string(name) + " has " +
                                  std::to_string(size) + " entries but position has " +
                                  std::to_string(n));
    }
  }
  return n;
}

}  // namespace rocklab::sim::output::detail
