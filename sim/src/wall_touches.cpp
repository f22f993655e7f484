#include "world_impl.h"

namespace rocklab::sim {

// A ball's contacts with a mesh wall: TriangleMeshIndex::touches gives every
// place where it touches the mesh once (one on a flat mesh, a ridge or an apex;
// two in a concave crease, three in a corner), and each becomes the contact of
// one of the wall's slots for this ball. Which slot: the one whose contact of
// the last force pass had the nearest normal, so a contact keeps its shear
// spring while the ball rolls along a crease or over a ridge; a new touch takes
// a free slot. With one touch at a time this is slot 0 throughout, the contact
// of a single-contact search bit for bit (and its spring carried as before).
void World::Impl::meshWallTouches(const detail::WallRuntime& runtime, std::size_t i,
                                  std::uint32_t c, WallTouches& out, bool bounded) const {
  out.slots = kMeshWallSlots;
  out.has.fill(false);
  out.fresh.fill(false);
  if (!runtime.active) return;
  const Vec3 x = p.position[i];
  const double r = p.radius[i];
  std::array<detail::WallContact, kMeshWallSlots> found;
  const std::size_t count =
      bounded ? runtime.meshTouches(x, r, nb.trianglesOf(c), found, nb.triangleDistancesOf(c),
                                    (x - nb.ref_position[i]).norm())
              : runtime.meshTouches(x, r, nb.trianglesOf(c), found);
  // Each touch, nearest first, continues the slot whose last normal is nearest.
  std::array<int, kMeshWallSlots> slot_of;
  slot_of.fill(-1);
  std::array<bool, kMeshWallSlots> taken{};
  for (std::size_t t = 0; t < count; ++t) {
    double best = kSameContactCos;
    for (std::uint32_t s = 0; s < kMeshWallSlots; ++s) {
      if (taken[s]) continue;
      const Vec3& last = history.wall_normal[c + s];
      const double cosine = last.dot(found[t].normal);  // 0 for a free slot (zero normal)
      if (cosine > best) {
        best = cosine;
        slot_of[t] = static_cast<int>(s);
      }
    }
    if (slot_of[t] >= 0) taken[static_cast<std::size_t>(slot_of[t])] = true;
  }
  // New touches: free slots first (their springs are zero, or a restored one of
  // a state saved without normals), then the slots of contacts that ended.
  for (std::size_t t = 0; t < count; ++t) {
    if (slot_of[t] >= 0) continue;
    int pick = -1;
    for (std::uint32_t s = 0; s < kMeshWallSlots && pick < 0; ++s)
      if (!taken[s] && history.wall_normal[c + s].isZero(0)) pick = static_cast<int>(s);
    for (std::uint32_t s = 0; s < kMeshWallSlots && pick < 0; ++s)
      if (!taken[s]) pick = static_cast<int>(s);
    slot_of[t] = pick;  // count <= kMeshWallSlots: there is one
    taken[static_cast<std::size_t>(pick)] = true;
    out.fresh[static_cast<std::size_t>(pick)] =
        !history.wall_normal[c + static_cast<std::uint32_t>(pick)].isZero(0);
  }
  for (std::size_t t = 0; t < count; ++t) {
    const auto s = static_cast<std::size_t>(slot_of[t]);
    ContactPoint& g = out.touch[s];
    g.normal = found[t].normal;
    g.overlap = found[t].overlap;
    g.point = x + g.normal * (r - 0.5 * g.overlap);
    out.has[s] = true;
  }
}

}  // namespace rocklab::sim
