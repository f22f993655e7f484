#pragma once
// Size check shared by the snapshot writers (run file, VTK series). Internal to
// rocklab_sim; needs neither HDF5 nor VTK.
#include <cmath>
#include <cstddef>
#include <optional>
#include <sstream>
#include <type_traits>
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

/// What is wrong with a snapshot's arrays: the array, the row and why.
struct ArrayProblem {
  const char* array;
  std::size_t row;
  std::string what;
};

/// The first problem of the bond arrays (ROCKLAB_SNAPSHOT_FIELDS: Bond) of a
/// snapshot of `balls` balls, or none: every bond array as long as bond_intact
/// (the row named is that length), ends that are existing, distinct balls,
/// intact 0 or 1.
inline std::optional<ArrayProblem> bondProblem(const Snapshot& s, std::size_t balls) {
  const std::size_t m = s.bond_intact.size();
#define ROCKLAB_BOND_SIZE(type, name, index, unit, frame, meaning)                          \
  if (SnapshotIndex::index == SnapshotIndex::Bond && s.name.size() != m)                   \
    return ArrayProblem{#name, s.name.size(),                                                \
                       "has " + std::to_string(s.name.size()) + " rows but bond_intact has " + \
                           std::to_string(m)};
  ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_BOND_SIZE)
#undef ROCKLAB_BOND_SIZE
  for (std::size_t k = 0; k < m; ++k) {
    for (const auto& [name, end] : {std::pair{"bond_a", s.bond_a[k]}, std::pair{"bond_b", s.bond_b[k]}})
      if (end >= balls)
        return ArrayProblem{name, k, "ball " + std::to_string(end) + " does not exist (the frame has " +
                                        std::to_string(balls) + " balls)"};
    if (s.bond_a[k] == s.bond_b[k])
      return ArrayProblem{"bond_b", k, "joins ball " + std::to_string(s.bond_a[k]) + " to itself"};
    if (s.bond_intact[k] > 1)
      return ArrayProblem{"bond_intact", k, "value " + std::to_string(s.bond_intact[k]) + " (allowed: 0, 1)"};
  }
  return std::nullopt;
}

namespace frame_check {
inline bool finite(double v) { return std::isfinite(v); }
inline bool finite(const geometry::Vec3& v) { return v.allFinite(); }
inline bool finite(const geometry::Quat& q) { return q.coeffs().allFinite(); }
template <class T>
std::string show(const T& v) {
  std::ostringstream s;
  s.precision(6);
  if constexpr (std::is_same_v<T, geometry::Vec3>)
    s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  else if constexpr (std::is_same_v<T, geometry::Quat>)
    s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ", " << v.w() << ")";
  else
    s << +v;
  return s.str();
}
}  // namespace frame_check

/// The first problem of a snapshot read back from a file, before anything uses
/// it: every array as long as its index says (balls, clumps, bonds; arrays a
/// frame never holds may be empty), every number finite, radii > 0, clump
/// orientations unit quaternions, clump indices -1 or an existing clump,
/// wall_active 0 or 1, and the bond arrays (bondProblem). Indices into the
/// scene's tables (material, wall) are the scene's to check.
inline std::optional<ArrayProblem> frameProblem(const Snapshot& s) {
  using frame_check::finite;
  using frame_check::show;
  const std::size_t n = s.position.size();
  const std::size_t c = s.clump_position.size();
  const auto length = [&](const char* name, std::size_t size, std::size_t wanted, const char* of) {
    return ArrayProblem{name, size, "has " + std::to_string(size) + " rows but " + of + " has " + std::to_string(wanted)};
  };
#define ROCKLAB_FRAME_SIZE(type, name, index, unit, frame, meaning)                                     \
  if (FrameWrite::frame != FrameWrite::Never) {                                                        \
    if (SnapshotIndex::index == SnapshotIndex::Ball && s.name.size() != n &&                           \
        (FrameWrite::frame == FrameWrite::Always || !s.name.empty() || (#name == std::string("clump") && c > 0))) \
      return length(#name, s.name.size(), n, "position");                                             \
    if (SnapshotIndex::index == SnapshotIndex::Clump && s.name.size() != c)                            \
      return length(#name, s.name.size(), c, "clump_position");                                       \
  }
  ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_FRAME_SIZE)
#undef ROCKLAB_FRAME_SIZE
#define ROCKLAB_FRAME_FINITE(type, name, index, unit, frame, meaning)                                   \
  if constexpr (!std::is_integral_v<type>)                                                              \
    for (std::size_t k = 0; k < s.name.size(); ++k)                                                     \
      if (!finite(s.name[k])) return ArrayProblem{#name, k, show(s.name[k]) + " (allowed: finite numbers)"};
  ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_FRAME_FINITE)
#undef ROCKLAB_FRAME_FINITE
  for (std::size_t k = 0; k < n; ++k)
    if (!(s.radius[k] > 0)) return ArrayProblem{"radius", k, show(s.radius[k]) + " m (allowed: > 0 m)"};
  for (std::size_t k = 0; k < s.clump.size(); ++k)
    if (s.clump[k] < -1 || s.clump[k] >= static_cast<std::int64_t>(c))
      return ArrayProblem{"clump", k,
                          show(s.clump[k]) + " (allowed: -1 for a free ball" +
                              (c > 0 ? ", or 0 to " + std::to_string(c - 1) + ", the frame has " + std::to_string(c) + " clumps)"
                                     : ", the frame has no clumps)")};
  for (std::size_t k = 0; k < c; ++k)
    if (!(std::abs(s.clump_orientation[k].norm() - 1.0) <= 1e-6))
      return ArrayProblem{"clump_orientation", k, show(s.clump_orientation[k]) + " (allowed: a unit quaternion)"};
  for (std::size_t k = 0; k < s.wall_active.size(); ++k)
    if (s.wall_active[k] > 1) return ArrayProblem{"wall_active", k, show(s.wall_active[k]) + " (allowed: 0, 1)"};
  return bondProblem(s, n);
}

}  // namespace rocklab::sim::output::detail
