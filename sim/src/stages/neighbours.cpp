#include "../world_impl.h"

namespace rocklab::sim {

// Stage 2, neighbours.
// Reads: positions, radii, clump membership, intact contact bonds, wall poses; the old lists.
// Writes: nb (pair list, wall candidates, reference positions), the contact
// history and relaxation offsets carried over to the new lists (and the shear
// springs of broken contact bonds' pairs: bonds.handover, emptied), the thread
// ranges and cross-pair slots of the force pass (scratch); relaxation factor.

void World::Impl::neighbourStage() {
  if (nb.need_rebuild) rebuildNeighbours();
  if (relax.pending) startRelaxation();
  if (relax.active()) updateRelaxation();
}

void World::Impl::rebuildNeighbours() {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = p.size();
  detail::PairList old = std::move(nb.pairs);
  std::vector<Vec3> old_shear = std::move(history.pair_shear);
  std::vector<double> old_relax = std::move(relax.pair);
  const bool carry_relax = relax.active();
  // Pairs held by intact contact bonds (§8.1) have no ordinary contact.
  const std::vector<std::uint64_t> bonded =
      bonds.contact_intact > 0 ? contactBondedPairs() : std::vector<std::uint64_t>{};
  nb.finder.build(p.position, p.radius, nb.skin, teamSize(), nb.pairs, model.max_grid_levels, p.clump,
                  bonded);
  const std::size_t np = nb.pairs.size();
  history.pair_shear.assign(np, Vec3::Zero());
  history.pair_touch.assign(np, 0);
  if (carry_relax) relax.pair.assign(np, 0.0);
  // Carry shear history over by merging old and new rows (both sorted by j).
  if (!old.row_offset.empty()) {
#pragma omp parallel for schedule(static) num_threads(teamSize())
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t a = old.row_offset[i], b = nb.pairs.row_offset[i];
      const std::uint32_t ae = old.row_offset[i + 1], be = nb.pairs.row_offset[i + 1];
      while (a < ae && b < be) {
        if (old.partner[a] < nb.pairs.partner[b]) ++a;
        else if (old.partner[a] > nb.pairs.partner[b]) ++b;
        else {
          if (carry_relax) relax.pair[b] = old_relax[a];
          history.pair_shear[b++] = old_shear[a++];
        }
      }
    }
  }
  if (!bonds.handover.empty()) takeHandovers();  // pairs of contact bonds broken since the last build
  // Wall candidates: balls within r + skin of an active wall.
  // A mesh wall takes kMeshWallSlots candidates (wall_touches.cpp), in a row.
  std::vector<std::uint32_t> old_offset = std::move(nb.wall_offset), old_index = std::move(nb.wall_index);
  std::vector<std::uint8_t> old_slot = std::move(nb.wall_slot);
  std::vector<Vec3> old_wshear = std::move(history.wall_shear);
  std::vector<Vec3> old_wnormal = std::move(history.wall_normal);
  std::vector<double> old_wrelax = std::move(relax.wall);
  std::vector<std::uint32_t> old_tri_offset = std::move(nb.wall_triangle_offset);
  std::vector<std::uint32_t> old_triangles = std::move(nb.wall_triangles);
  std::vector<double> old_tri_distance = std::move(nb.wall_triangle_distance);
  nb.wall_offset.assign(n + 1, 0);
  nb.wall_index.clear();
  nb.wall_slot.clear();
  nb.wall_triangle_offset.assign(1, 0);
  nb.wall_triangles.clear();
  nb.wall_triangle_distance.clear();
  // A mesh wall active at the last build and not moved since (a static wall, or the
  // held walls of a breakage freeze): a ball at exactly its position of then gets its
  // triangles of then, which the same search would return again. In a freeze most
  // balls are held still, and the searches took a tenth of the sigma0 = 0.8 MPa run
  // (perf, docs/crusher.md).
  std::vector<std::uint8_t> wall_unchanged(walls.size(), 0);
  if (old_offset.size() == n + 1 && nb.ref_position.size() == n && nb.wall_active_at_build.size() == walls.size())
    for (std::size_t k = 0; k < walls.size(); ++k)
      wall_unchanged[k] = model.walls[k].shape == WallShape::Mesh && walls[k].active &&
                          nb.wall_active_at_build[k] && walls[k].displacementSinceReference() == 0.0;
  const auto nearWall = [&](std::size_t i, std::size_t k) {
    if (wall_unchanged[k] && p.position[i] == nb.ref_position[i]) {
      for (std::uint32_t o = old_offset[i]; o < old_offset[i + 1]; ++o)
        if (old_index[o] == k && old_slot[o] == 0) {
          nb.wall_triangles.insert(nb.wall_triangles.end(), old_triangles.begin() + old_tri_offset[o],
                                   old_triangles.begin() + old_tri_offset[o + 1]);
          nb.wall_triangle_distance.insert(nb.wall_triangle_distance.end(),
                                           old_tri_distance.begin() + old_tri_offset[o],
                                           old_tri_distance.begin() + old_tri_offset[o + 1]);
          return true;
        }
      return false;  // not near it then, so not now
    }
    return walls[k].near(model.walls[k], p.position[i], p.radius[i] + nb.skin, nb.wall_triangles,
                         nb.wall_triangle_distance);
  };
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < walls.size(); ++k) {
      if (!walls[k].active) continue;
      if (!nearWall(i, k)) continue;
      const std::uint32_t slots = model.walls[k].shape == WallShape::Mesh ? kMeshWallSlots : 1;
      for (std::uint32_t s = 0; s < slots; ++s) {
        nb.wall_index.push_back(static_cast<std::uint32_t>(k));
        nb.wall_slot.push_back(static_cast<std::uint8_t>(s));
        nb.wall_triangle_offset.push_back(static_cast<std::uint32_t>(nb.wall_triangles.size()));
      }
    }
    nb.wall_offset[i + 1] = static_cast<std::uint32_t>(nb.wall_index.size());
  }
  history.wall_shear.assign(nb.wall_index.size(), Vec3::Zero());
  history.wall_touch.assign(nb.wall_index.size(), 0);
  if (has_mesh_walls) history.wall_normal.assign(nb.wall_index.size(), Vec3::Zero());
  if (carry_relax) relax.wall.assign(nb.wall_index.size(), 0.0);
  if (!old_offset.empty()) {
    for (std::size_t i = 0; i < n; ++i)
      for (std::uint32_t c = nb.wall_offset[i]; c < nb.wall_offset[i + 1]; ++c)
        for (std::uint32_t o = old_offset[i]; o < old_offset[i + 1]; ++o)
          if (old_index[o] == nb.wall_index[c] && old_slot[o] == nb.wall_slot[c]) {
            history.wall_shear[c] = old_wshear[o];
            if (has_mesh_walls) history.wall_normal[c] = old_wnormal[o];
            if (carry_relax) relax.wall[c] = old_wrelax[o];
          }
  }
  nb.ref_position = p.position;
  nb.wall_active_at_build.resize(walls.size());
  for (std::size_t k = 0; k < walls.size(); ++k) nb.wall_active_at_build[k] = walls[k].active;
  for (auto& wr : walls) wr.setReference();
  nb.last_max_disp2 = 0.0;
  nb.need_rebuild = false;
  assignRanges();
  ++stats.neighbour_rebuilds;
  stats.pairs_in_list = np;
  stats.wall_candidates = static_cast<std::size_t>(std::count(nb.wall_slot.begin(), nb.wall_slot.end(), 0));
  stats.neighbour_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void World::Impl::assignRanges() {
  const std::size_t n = p.size();
  const int team = teamSize();
  scratch.range_begin.resize(static_cast<std::size_t>(team) + 1);
  for (int t = 0; t <= team; ++t) scratch.range_begin[t] = static_cast<std::uint32_t>(n * static_cast<std::size_t>(t) / team);
  const auto lists = {&scratch.cross_begin, &scratch.cross_ball, &scratch.cross_pair,
                      &scratch.receive_begin, &scratch.receive_ball, &scratch.receive_slot};
  for (auto* v : lists) v->clear();
  if (team == 1) {  // one thread: no pair crosses two ranges
    for (auto* v : lists) v->shrink_to_fit();
    scratch.cross.clear();
    return;
  }
  scratch.cross_begin.push_back(0);
  for (int t = 0; t < team; ++t) {
    for (std::uint32_t i = scratch.range_begin[t]; i < scratch.range_begin[t + 1]; ++i)
      for (std::uint32_t k = nb.pairs.row_offset[i]; k < nb.pairs.row_offset[i + 1]; ++k)
        if (nb.pairs.partner[k] >= scratch.range_begin[t + 1]) {
          scratch.cross_ball.push_back(i);
          scratch.cross_pair.push_back(k);
        }
    scratch.cross_begin.push_back(static_cast<std::uint32_t>(scratch.cross_pair.size()));
  }
  const std::size_t slots = scratch.cross_pair.size();
  scratch.cross.resize(slots);
  // Receivers: the slots sorted by second ball; the stable sort keeps ascending
  // first ball within one (the slots are in ascending first ball), the order in
  // which a ball sums what it receives on any number of threads.
  std::vector<std::uint32_t> order(slots);
  for (std::uint32_t s = 0; s < slots; ++s) order[s] = s;
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return nb.pairs.partner[scratch.cross_pair[a]] < nb.pairs.partner[scratch.cross_pair[b]];
  });
  scratch.receive_ball.resize(slots);
  scratch.receive_slot = std::move(order);
  scratch.receive_begin.assign(static_cast<std::size_t>(team) + 1, 0);
  int range = 0;
  for (std::size_t r = 0; r < slots; ++r) {
    const std::uint32_t j = nb.pairs.partner[scratch.cross_pair[scratch.receive_slot[r]]];
    scratch.receive_ball[r] = j;
    while (j >= scratch.range_begin[range + 1]) scratch.receive_begin[++range] = static_cast<std::uint32_t>(r);
  }
  while (range < team) scratch.receive_begin[++range] = static_cast<std::uint32_t>(slots);
}

}  // namespace rocklab::sim
