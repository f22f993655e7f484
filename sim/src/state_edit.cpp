// Removal of bodies from a saved state (see withoutBalls in world.h), and free
// spheres added to one.
#include <cstdint>
#include <stdexcept>

#include "rocklab/sim/world.h"

namespace rocklab::sim {

namespace {

/// Keeps the entries of `v` whose flag in `keep` is set, in order.
template <class T>
void compact(std::vector<T>& v, const std::vector<bool>& keep) {
  std::size_t out = 0;
  for (std::size_t k = 0; k < v.size(); ++k)
    if (keep[k]) v[out++] = v[k];
  v.resize(out);
}

}  // namespace

WorldState withoutBalls(WorldState state, std::vector<bool> remove) {
  ParticleState& p = state.particles;
  const std::size_t n = p.size();
  if (remove.size() != n) throw std::invalid_argument("withoutBalls: one flag per ball is needed");
  ClumpState& k = p.clumps;
  // A clump goes whole: one removed member removes all.
  std::vector<bool> keep_clump(k.size(), true);
  for (std::size_t c = 0; c < k.size(); ++c) {
    for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m)
      if (remove[k.member_ball[m]]) keep_clump[c] = false;
    if (!keep_clump[c])
      for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) remove[k.member_ball[m]] = true;
  }
  std::vector<bool> keep(n);
  std::vector<std::uint32_t> new_index(n, UINT32_MAX);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    keep[i] = !remove[i];
    if (keep[i]) new_index[i] = next++;
  }
#define ROCKLAB_COMPACT(type, name, unit, meaning) compact(p.name, keep);
  ROCKLAB_BALL_FIELDS(ROCKLAB_COMPACT)
#undef ROCKLAB_COMPACT
  if (k.size() > 0) {
    std::vector<std::int32_t> new_clump(k.size(), -1);
    std::int32_t next_clump = 0;
    for (std::size_t c = 0; c < k.size(); ++c)
      if (keep_clump[c]) new_clump[c] = next_clump++;
    compact(p.clump, keep);
    for (std::int32_t& c : p.clump)
      if (c >= 0) c = new_clump[static_cast<std::size_t>(c)];
    std::vector<std::uint32_t> begin{0}, ball;
    std::vector<Vec3> offset;
    for (std::size_t c = 0; c < k.size(); ++c) {
      if (!keep_clump[c]) continue;
      for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
        ball.push_back(new_index[k.member_ball[m]]);
        offset.push_back(k.member_offset[m]);
      }
      begin.push_back(static_cast<std::uint32_t>(ball.size()));
    }
    k.member_begin = std::move(begin);
    k.member_ball = std::move(ball);
    k.member_offset = std::move(offset);
#define ROCKLAB_COMPACT(type, name, unit, meaning) compact(k.name, keep_clump);
    ROCKLAB_CLUMP_FIELDS(ROCKLAB_COMPACT)
#undef ROCKLAB_COMPACT
    if (k.size() == 0) {
      p.clump.clear();
      k = ClumpState{};
    }
  }
  std::vector<PairHistory> pairs;
  for (const PairHistory& h : state.pair_history)
    if (keep[h.i] && keep[h.j]) pairs.push_back({new_index[h.i], new_index[h.j], h.shear, h.relax_offset});
  state.pair_history = std::move(pairs);
  std::vector<WallHistory> walls;
  for (const WallHistory& h : state.wall_history)
    if (keep[h.particle]) {
      walls.push_back(h);
      walls.back().particle = new_index[h.particle];
    }
  state.wall_history = std::move(walls);
  BondState& bonds = state.bonds;
  std::vector<bool> keep_bond(bonds.size());
  for (std::size_t e = 0; e < bonds.size(); ++e) keep_bond[e] = keep[bonds.a[e]] && keep[bonds.b[e]];
#define ROCKLAB_COMPACT(type, name, unit, meaning) compact(bonds.name, keep_bond);
  ROCKLAB_BOND_FIELDS(ROCKLAB_COMPACT)
#undef ROCKLAB_COMPACT
  for (std::size_t e = 0; e < bonds.size(); ++e) {
    bonds.a[e] = new_index[bonds.a[e]];
    bonds.b[e] = new_index[bonds.b[e]];
  }
  return state;
}

void setFreeSphereMass(ParticleState& p, std::size_t i, double mass) {
  const double r = p.radius[i];
  p.mass[i] = mass;
  p.inv_mass[i] = 1.0 / mass;
  p.inv_inertia[i] = 1.0 / (0.4 * mass * r * r);  // Eq 2-8
}

std::uint32_t appendFreeSphere(ParticleState& p, const SphereSpec& s, double mass, std::uint64_t id) {
  const std::size_t i = p.size();
#define ROCKLAB_GROW(type, name, unit, meaning) p.name.emplace_back();
  ROCKLAB_BALL_FIELDS(ROCKLAB_GROW)
#undef ROCKLAB_GROW
  if (!p.clump.empty()) p.clump.push_back(-1);
  p.position[i] = s.position;
  p.velocity[i] = s.velocity;
  p.omega[i] = s.omega;
  p.radius[i] = s.radius;
  p.material[i] = s.material;
  p.id[i] = id;
  setFreeSphereMass(p, i, mass);
  return static_cast<std::uint32_t>(i);
}

}  // namespace rocklab::sim
