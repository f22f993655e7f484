#include "state_check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <vector>

namespace rocklab::sim::detail {

namespace {

// A step count a double still counts exactly (t = step dt is computed from it).
constexpr std::uint64_t kMaxStep = std::uint64_t{1} << 53;
// |q| of a stored orientation: written normalised, so only round-off may differ.
constexpr double kUnitTolerance = 1e-6;

std::string show(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}
std::string show(const Vec3& v) { return "(" + show(v.x()) + ", " + show(v.y()) + ", " + show(v.z()) + ")"; }
std::string show(const Quat& q) {
  return "(" + show(q.x()) + ", " + show(q.y()) + ", " + show(q.z()) + ", " + show(q.w()) + ")";
}
template <class T>
  requires std::is_integral_v<T>
std::string show(T v) {
  return std::to_string(+v);  // + : a uint8_t prints as a number
}

bool finite(double v) { return std::isfinite(v); }
bool finite(const Vec3& v) { return v.allFinite(); }
bool finite(const Quat& q) { return q.coeffs().allFinite(); }

/// Collects the first problem; later checks are skipped once one is found.
class Check {
 public:
  bool ok() const { return problem_.empty(); }
  std::string problem() const { return problem_; }

  void fail(const std::string& text) {
    if (ok()) problem_ = text;
  }
  /// "<dataset> row <k>: <value> (allowed: <allowed>)" for the first row `bad` flags.
  template <class T, class Bad>
  void rows(const std::string& dataset, const std::vector<T>& values, Bad bad, const std::string& allowed) {
    if (!ok()) return;
    for (std::size_t k = 0; k < values.size(); ++k)
      if (bad(values[k])) {
        fail(dataset + " row " + std::to_string(k) + ": " + show(values[k]) + " (allowed: " + allowed + ")");
        return;
      }
  }
  /// Every floating-point value finite (integer arrays pass).
  template <class T>
  void finiteRows(const std::string& dataset, const std::vector<T>& values) {
    if constexpr (!std::is_integral_v<T>) rows(dataset, values, [](const T& v) { return !finite(v); }, "finite");
  }
  /// Indices below `limit` (`what` says what they index).
  template <class T>
  void indexRows(const std::string& dataset, const std::vector<T>& values, std::size_t limit, std::int64_t lowest,
                 const std::string& what) {
    const std::string allowed = limit == 0 ? "none: " + what + " is empty"
                                           : show(lowest) + " to " + std::to_string(limit - 1) + ", " + what;
    rows(dataset, values,
         [&](T v) { return static_cast<std::int64_t>(v) < lowest || static_cast<std::int64_t>(v) >= static_cast<std::int64_t>(limit); },
         allowed);
  }
  void positive(const std::string& dataset, const std::vector<double>& values, const char* unit) {
    rows(dataset, values, [](double v) { return !(v > 0) || !std::isfinite(v); }, std::string("> 0 ") + unit + ", finite");
  }

 private:
  std::string problem_;
};

void checkSizes(Check& c, const WorldState& state) {
  c.fail(stateShapeProblem(state));
}

void checkRunValues(Check& c, const WorldState& s) {
  if (!(s.dt > 0) || !std::isfinite(s.dt)) c.fail("attribute dt: " + show(s.dt) + " s (allowed: > 0 s, finite)");
  if (!(s.time >= 0) || !std::isfinite(s.time))
    c.fail("attribute time: " + show(s.time) + " s (allowed: >= 0 s, finite)");
  if (s.step > kMaxStep) c.fail("attribute step: " + show(s.step) + " (allowed: 0 to 2^53)");
  if (!c.ok()) return;
  // The clock is t = step dt (integrate.cpp: finishStep), so the two must agree.
  const double expected = static_cast<double>(s.step) * s.dt;
  if (std::abs(s.time - expected) > 1e-9 * std::max(expected, s.dt))
    c.fail("attribute time: " + show(s.time) + " s but step " + show(s.step) + " x dt " + show(s.dt) + " s = " +
           show(expected) + " s (allowed: time = step x dt)");
}

void checkBalls(Check& c, const Model& model, const ParticleState& p) {
#define ROCKLAB_FINITE(type, name, unit, meaning) c.finiteRows("particles/" #name, p.name);
  ROCKLAB_BALL_FIELDS(ROCKLAB_FINITE)
#undef ROCKLAB_FINITE
  c.positive("particles/radius", p.radius, "m");
  c.positive("particles/mass", p.mass, "kg");
  c.positive("particles/inv_mass", p.inv_mass, "1/kg");
  c.positive("particles/inv_inertia", p.inv_inertia, "1/(kg m^2)");
  if (!c.ok()) return;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::abs(p.mass[i] * p.inv_mass[i] - 1.0) > 1e-9) {
      c.fail("particles/inv_mass row " + std::to_string(i) + ": " + show(p.inv_mass[i]) + " 1/kg (allowed: 1 / particles/mass = " +
             show(1.0 / p.mass[i]) + ")");
      return;
    }
  c.indexRows("particles/material", p.material, model.materials.size(), 0,
              "the scene has " + std::to_string(model.materials.size()) + " materials");
  if (!c.ok()) return;
  // Ids name bodies in outputs and marker lists: one body, one id.
  std::vector<std::pair<std::uint64_t, std::size_t>> ids;
  ids.reserve(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) ids.emplace_back(p.id[i], i);
  std::sort(ids.begin(), ids.end());
  for (std::size_t k = 1; k < ids.size(); ++k)
    if (ids[k].first == ids[k - 1].first) {
      c.fail("particles/id row " + std::to_string(ids[k].second) + ": " + show(ids[k].first) + " is also the id of row " +
             std::to_string(ids[k - 1].second) + " (allowed: each id once)");
      return;
    }
}

void checkClumps(Check& c, const ParticleState& p) {
  const ClumpState& k = p.clumps;
  if (k.size() == 0) {
    c.rows("particles/clump", p.clump, [](std::int32_t v) { return v != -1; }, "-1, the state has no clumps");
    return;
  }
#define ROCKLAB_FINITE(type, name, unit, meaning) c.finiteRows("clumps/" #name, k.name);
  ROCKLAB_CLUMP_FIELDS(ROCKLAB_FINITE)
#undef ROCKLAB_FINITE
  c.finiteRows("clumps/member_offset", k.member_offset);
  c.positive("clumps/mass", k.mass, "kg");
  c.rows("clumps/inertia", k.inertia, [](const Vec3& v) { return !(v.minCoeff() > 0); }, "every moment > 0 kg m^2");
  c.rows("clumps/orientation", k.orientation,
         [](const Quat& q) { return !(std::abs(q.norm() - 1.0) <= kUnitTolerance); }, "a unit quaternion, |q| = 1");
  c.indexRows("particles/clump", p.clump, k.size(), -1, "-1 for a free ball");
  c.indexRows("clumps/member_ball", k.member_ball, p.size(), 0, "the state has " + std::to_string(p.size()) + " balls");
  if (!c.ok()) return;
  if (k.member_begin.front() != 0) c.fail("clumps/member_begin row 0: " + show(k.member_begin.front()) + " (allowed: 0)");
  for (std::size_t b = 0; c.ok() && b < k.size(); ++b)
    if (k.member_begin[b + 1] <= k.member_begin[b])
      c.fail("clumps/member_begin row " + std::to_string(b + 1) + ": " + show(k.member_begin[b + 1]) +
             " (allowed: more than row " + std::to_string(b) + ", " + show(k.member_begin[b]) + ": a clump has members)");
  if (!c.ok()) return;
  // Every member is listed once, under the clump particles/clump names.
  std::vector<std::uint8_t> listed(p.size(), 0);
  for (std::size_t b = 0; b < k.size(); ++b)
    for (std::uint32_t m = k.member_begin[b]; m < k.member_begin[b + 1]; ++m) {
      const std::uint32_t i = k.member_ball[m];
      if (p.clump[i] != static_cast<std::int32_t>(b) || listed[i]) {
        c.fail("clumps/member_ball row " + std::to_string(m) + ": ball " + show(i) + (listed[i] ? " listed twice" : "") +
               " (allowed: a ball whose particles/clump is " + std::to_string(b) + ", once)");
        return;
      }
      listed[i] = 1;
    }
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.clump[i] >= 0 && !listed[i]) {
      c.fail("particles/clump row " + std::to_string(i) + ": " + show(p.clump[i]) +
             " (allowed: a clump that lists the ball in clumps/member_ball, or -1)");
      return;
    }
}

template <class History>
void checkHistory(Check& c, const std::string& group, const std::vector<History>& rows) {
  std::vector<Vec3> shear;
  std::vector<double> offset;
  for (const History& h : rows) {
    shear.push_back(h.shear);
    offset.push_back(h.relax_offset);
  }
  c.finiteRows(group + "/shear", shear);
  c.rows(group + "/relax_offset", offset, [](double v) { return !(v >= 0) || !std::isfinite(v); }, ">= 0 m, finite");
}

void checkContacts(Check& c, const Model& model, const WorldState& s) {
  const std::size_t n = s.particles.size();
  std::vector<std::uint32_t> i, j, particle, wall;
  for (const PairHistory& h : s.pair_history) {
    i.push_back(h.i);
    j.push_back(h.j);
  }
  for (const WallHistory& h : s.wall_history) {
    particle.push_back(h.particle);
    wall.push_back(h.wall);
  }
  const std::string balls = "the state has " + std::to_string(n) + " balls";
  c.indexRows("pairs/i", i, n, 0, balls);
  c.indexRows("pairs/j", j, n, 0, balls);
  for (std::size_t k = 0; c.ok() && k < i.size(); ++k)
    if (!(i[k] < j[k]))
      c.fail("pairs/j row " + std::to_string(k) + ": " + show(j[k]) + " (allowed: more than pairs/i, " + show(i[k]) + ")");
  checkHistory(c, "pairs", s.pair_history);
  c.indexRows("walls/particle", particle, n, 0, balls);
  c.indexRows("walls/wall", wall, model.walls.size(), 0, "the scene has " + std::to_string(model.walls.size()) + " walls");
  checkHistory(c, "walls", s.wall_history);
  std::vector<Vec3> normal;
  for (std::size_t k = 0; c.ok() && k < s.wall_history.size(); ++k) {
    const WallHistory& h = s.wall_history[k];
    normal.push_back(h.normal);
    const bool mesh = model.walls[h.wall].shape == WallShape::Mesh;
    if (h.slot >= (mesh ? kMeshWallSlots : 1))
      c.fail("walls/slot row " + std::to_string(k) + ": " + show(h.slot) + " (allowed: " +
             (mesh ? "0 to " + std::to_string(kMeshWallSlots - 1) + " for the mesh wall '"
                   : "0 for the wall '") + model.walls[h.wall].name + "')");
  }
  if (c.ok()) c.finiteRows("walls/normal", normal);
}

void checkBonds(Check& c, const WorldState& s) {
  const BondState& b = s.bonds;
  // Strengths may be +infinity (an unbreakable bond: BondSpec's default).
#define ROCKLAB_FINITE(type, name, unit, meaning) \
  if (std::string_view(#name).find("strength") == std::string_view::npos) c.finiteRows("bonds/" #name, b.name);
  ROCKLAB_BOND_FIELDS(ROCKLAB_FINITE)
#undef ROCKLAB_FINITE
  c.rows("bonds/tensile_strength", b.tensile_strength, [](double v) { return !(v > 0); }, "> 0, or inf");
  c.rows("bonds/shear_strength", b.shear_strength, [](double v) { return !(v > 0); }, "> 0, or inf");
  const std::size_t n = s.particles.size();
  const std::string balls = "the state has " + std::to_string(n) + " balls";
  c.indexRows("bonds/a", b.a, n, 0, balls);
  c.indexRows("bonds/b", b.b, n, 0, balls);
  c.rows("bonds/kind", b.kind, [](std::uint8_t v) { return v > 1; }, "0 parallel, 1 contact");
  c.rows("bonds/intact", b.intact, [](std::uint8_t v) { return v > 1; }, "0, 1");
  // The rest (ends distinct, strengths, springs, normals) is the scene's bond check (world_setup.cpp).
}

}  // namespace

std::string stateShapeProblem(const WorldState& state) {
  const ParticleState& p = state.particles;
  const std::size_t n = p.size();
#define ROCKLAB_SIZE(type, name, unit, meaning) {#name, p.name.size()},
  const std::pair<const char*, std::size_t> sizes[] = {ROCKLAB_BALL_FIELDS(ROCKLAB_SIZE)};
#undef ROCKLAB_SIZE
  for (const auto& [name, size] : sizes)
    if (size != n)
      return "inconsistent array sizes: particles/" + std::string(name) + " has " + std::to_string(size) +
             " entries but particles/position has " + std::to_string(n);
  const ClumpState& k = p.clumps;
  const std::size_t nc = k.size();
#define ROCKLAB_SIZE(type, name, unit, meaning) {#name, k.name.size()},
  const std::pair<const char*, std::size_t> clump_sizes[] = {ROCKLAB_CLUMP_FIELDS(ROCKLAB_SIZE)};
#undef ROCKLAB_SIZE
  for (const auto& [name, size] : clump_sizes)
    if (size != nc)
      return "inconsistent array sizes: clumps/" + std::string(name) + " has " + std::to_string(size) +
             " entries but clumps/position has " + std::to_string(nc);
  if (nc > 0) {
    if (p.clump.size() != n) return "particles/clump must have one entry per particle";
    if (k.member_begin.size() != nc + 1 || k.member_begin.back() != k.member_ball.size() ||
        k.member_offset.size() != k.member_ball.size())
      return "inconsistent clump member arrays";
  } else if (!p.clump.empty() && p.clump.size() != n) {
    return "particles/clump must have one entry per particle";
  }
  const BondState& b = state.bonds;
#define ROCKLAB_SIZE(type, name, unit, meaning) {#name, b.name.size()},
  const std::pair<const char*, std::size_t> bond_sizes[] = {ROCKLAB_BOND_FIELDS(ROCKLAB_SIZE)};
#undef ROCKLAB_SIZE
  for (const auto& [name, size] : bond_sizes)
    if (size != b.size())
      return "inconsistent array sizes: bonds/" + std::string(name) + " has " + std::to_string(size) +
             " entries but bonds/a has " + std::to_string(b.size());
  return {};
}

std::string stateProblem(const Model& model, const WorldState& state) {
  Check c;
  checkSizes(c, state);
  checkRunValues(c, state);
  checkBalls(c, model, state.particles);
  checkClumps(c, state.particles);
  checkContacts(c, model, state);
  checkBonds(c, state);
  return c.problem();
}

}  // namespace rocklab::sim::detail
