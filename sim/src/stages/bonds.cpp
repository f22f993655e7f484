#include <numbers>
#include <sstream>

#include "../world_impl.h"

namespace rocklab::sim {

// Stage 4, bonds: every intact parallel bond (bonds.h, dem-models.md §8.2) is
// updated from the relative motion of its two balls, checked against its
// strengths, and its force and moment are added into the balls' accumulators;
// so is every intact contact bond (§8.1, its update in contact_bonds.cpp).
// Reads: positions at t, velocities and spins at t - dt/2; bonds.state.
// Writes: bonds.state (forces, moments, frame; intact -> 0 on breakage), the
// per-bond scratch, scratch.acc_force/acc_torque (adds), bonds.breaks; after a
// contact bond breaks, bonds.handover and nb.need_rebuild (its pair rejoins the
// neighbour list at the next step); the overlap check of contact-bonded pairs.
//
// Threads: the update runs over bonds (each writes only its own entries), the
// sums over balls, each adding its bonds in ascending bond order: bitwise the
// same on any number of threads.

const char* bondFailureModeName(BondFailureMode mode) {
  return mode == BondFailureMode::Tensile ? "tensile" : "shear";
}

const char* bondKindName(BondKind kind) { return kind == BondKind::Parallel ? "parallel" : "contact"; }

BondDisc bondDisc(double radius) {
  BondDisc d;
  d.radius = radius;
  const double r2 = radius * radius;
  d.area = std::numbers::pi * r2;                 // Eq 2-36
  d.polar = 0.5 * std::numbers::pi * r2 * r2;     // Eq 2-37
  d.inertia = 0.25 * std::numbers::pi * r2 * r2;  // Eq 2-38
  return d;
}

BondStress bondStress(const BondDisc& d, double normal_force, const Vec3& shear_force,
                      double twist_moment, const Vec3& bend_moment) {
  BondStress s;
  s.tensile = -normal_force / d.area + bend_moment.norm() * d.radius / d.inertia;  // Eq 2-33 [R]
  s.shear =
      shear_force.norm() / d.area + std::abs(twist_moment) * d.radius / d.polar;  // Eq 2-34 [R]
  return s;
}

namespace {

/// How a bond's contact plane turned in one step: tilted from the normal n_old
/// to n, and spun about n by the mean of the balls' spins. Computed once per
/// bond and applied to its shear force and its bending moment.
struct PlaneTurn {
  Vec3 n, k;   // k = n_old x n, |k| = sin of the tilt
  double c;    // cos of the tilt
  bool tilts;  // false when the normal turned over in one step (no defined rotation)
  double sin_spin, cos_spin;

  PlaneTurn(const Vec3& n_old, const Vec3& n_new, double spin) : n(n_new), k(n_old.cross(n_new)) {
    c = n_old.dot(n_new);
    tilts = c > -1.0 + 1e-12;
    // The series is exact to round-off for the tiny angles of one step and
    // saves two trigonometric calls.
    if (std::abs(spin) < 1e-3) {
      const double a2 = spin * spin;
      sin_spin = spin * (1.0 - a2 / 6.0);
      cos_spin = 1.0 - 0.5 * a2 * (1.0 - a2 / 12.0);
    } else {
      sin_spin = std::sin(spin);
      cos_spin = std::cos(spin);
    }
  }

  /// v (in the old plane) carried into the new one: the tilt by Rodrigues with
  /// the unnormalised axis k (k (k.v) (1 - cos) / sin^2 = k (k.v) / (1 + cos)),
  /// then the spin about n, then any round-off drift out of the plane removed.
  [[gnu::always_inline]] Vec3 carry(const Vec3& v) const {
    const Vec3 tilted = tilts ? Vec3(c * v + k.cross(v) + k * (k.dot(v) / (1.0 + c))) : v;
    const Vec3 r = cos_spin * tilted + sin_spin * n.cross(tilted);
    return r - r.dot(n) * n;
  }
};

// The step checks merged across threads (mergeChecks: max and or, any order).
#pragma omp declare reduction(mergeStepChecks : StepChecks : mergeChecks(omp_out, omp_in)) \
    initializer(omp_priv = StepChecks{})

}  // namespace

void World::Impl::bondStage(StepChecks& checks) {
  BondState& s = bonds.state;
  const ParallelBondModel& bm = model.bonds;
  const double kn = bm.normal_stiffness, ks = bm.shear_stiffness;
  const bool combined = bm.failure_rule == BondFailureRule::Combined;
  const auto nbonds = static_cast<std::ptrdiff_t>(s.size());
  const double h = dt;
  constexpr auto kContact = static_cast<std::uint8_t>(BondKind::Contact);
  bool any_broke = false;
  StepChecks bonded;  // the overlaps of contact-bonded pairs
  // clang-format off
#pragma omp parallel for schedule(static) num_threads(bondTeamSize()) \
    reduction(|| : any_broke) reduction(mergeStepChecks : bonded)
  // clang-format on
  for (std::ptrdiff_t kk = 0; kk < nbonds; ++kk) {
    const auto k = static_cast<std::size_t>(kk);
    bonds.broke[k] = 0;
    if (!s.intact[k]) continue;
    if (s.kind[k] == kContact) {
      if (const std::uint8_t how = contactBondStepAny(k, bonded)) {
        s.intact[k] = 0;
        bonds.broke[k] = how;
        any_broke = true;
      }
      continue;
    }
    const std::uint32_t a = s.a[k], b = s.b[k];
    const Vec3& xa = p.position[a];
    const Vec3& xb = p.position[b];
    const Vec3 d = xb - xa;
    const double dist = d.norm();
    const Vec3 n_old = s.normal[k];
    const Vec3 n = dist > 0 ? Vec3(d / dist) : n_old;
    const Vec3 xc = bondPoint(xa, p.radius[a], p.radius[b], n, dist);
    // Stored shear force and bending moment turn with the contact plane: its
    // tilt (n_old -> n) and its spin about n, the mean of the balls' spins.
    const PlaneTurn turn(n_old, n, 0.5 * (p.omega[a] + p.omega[b]).dot(n) * h);
    // Increments (Eq 2-29..2-32): relative motion of b against a at the bond.
    const Vec3 v_rel =
        (p.velocity[b] + p.omega[b].cross(xc - xb)) - (p.velocity[a] + p.omega[a].cross(xc - xa));
    const double du_n = v_rel.dot(n) * h;  // > 0 when separating
    const Vec3 du_s = (v_rel - v_rel.dot(n) * n) * h;
    const Vec3 dtheta = (p.omega[b] - p.omega[a]) * h;
    const double dtheta_n = dtheta.dot(n);
    const Vec3 dtheta_s = dtheta - dtheta_n * n;
    const BondDisc disc = bondDisc(s.radius[k]);
    const double fn = s.normal_force[k] - kn * disc.area * du_n;               // Eq 2-29
    const Vec3 fs = turn.carry(s.shear_force[k]) - (ks * disc.area) * du_s;    // Eq 2-30 [R]
    const double mn = s.twist_moment[k] - ks * disc.polar * dtheta_n;          // Eq 2-31 [R]
    const Vec3 ms = turn.carry(s.bend_moment[k]) - (kn * disc.inertia) * dtheta_s;  // Eq 2-32
    s.normal[k] = n;
    s.normal_force[k] = fn;
    s.shear_force[k] = fs;
    s.twist_moment[k] = mn;
    s.bend_moment[k] = ms;

    const BondStress stress = bondStress(disc, fn, fs, mn, ms);
    double tensile_ratio, shear_ratio;
    if (combined) {
      // Each force or moment against its own capacity; the parts add up.
      tensile_ratio = std::max(-fn, 0.0) / (s.tensile_strength[k] * disc.area) +
                      ms.norm() * disc.radius / (s.tensile_strength[k] * disc.inertia);
      shear_ratio = fs.norm() / (s.shear_strength[k] * disc.area) +
                    std::abs(mn) * disc.radius / (s.shear_strength[k] * disc.polar);
    } else {
      tensile_ratio = stress.tensile / s.tensile_strength[k];
      shear_ratio = stress.shear / s.shear_strength[k];
    }
    const bool broke = combined ? tensile_ratio + shear_ratio >= 1.0
                                : (tensile_ratio >= 1.0 || shear_ratio >= 1.0);
    if (broke) {
      // Deleted at once (ref §8.2): it carries nothing in the step it breaks, so
      // a pair whose bond breaks at once moves exactly as if never bonded.
      s.intact[k] = 0;
      bonds.broke[k] = tensile_ratio >= shear_ratio ? Bonds::kTensile : Bonds::kShear;
      bonds.force_b[k].setZero();
      bonds.torque_a[k].setZero();
      bonds.torque_b[k].setZero();
      any_broke = true;
      continue;
    }
    const Vec3 f = fn * n + fs;  // on b (Eq 2-27)
    const Vec3 m = mn * n + ms;  // on b (Eq 2-28)
    bonds.force_b[k] = f;
    bonds.torque_b[k] = m + (xc - xb).cross(f);
    bonds.torque_a[k] = -m - (xc - xa).cross(f);
  }
  mergeChecks(checks, bonded);
  if (any_broke) {
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (!bonds.broke[k]) continue;
      --bonds.intact;
      BondBreak e;
      e.time = time;
      e.step = step;
      e.bond = static_cast<std::uint32_t>(k);
      e.a = s.a[k];
      e.b = s.b[k];
      e.kind = static_cast<BondKind>(s.kind[k]);
      e.mode = bonds.broke[k] & Bonds::kTensile ? BondFailureMode::Tensile : BondFailureMode::Shear;
      e.normal_force = s.normal_force[k];
      e.shear_force = s.shear_force[k].norm();
      if (s.kind[k] == kContact) {
        --bonds.contact_intact;
        nb.need_rebuild = true;  // its pair rejoins the neighbour list
        if (bonds.broke[k] & Bonds::kActs)
          bonds.handover.push_back({std::min(e.a, e.b), std::max(e.a, e.b), bonds.handover_shear[k], 0.0});
      } else {
        const BondStress stress = bondStress(bondDisc(s.radius[k]), s.normal_force[k], s.shear_force[k],
                                             s.twist_moment[k], s.bend_moment[k]);
        e.tensile_stress = stress.tensile;
        e.shear_stress = stress.shear;
      }
      bonds.breaks.push_back(e);
    }
  }
  // The gather through raw pointers and a running sum per ball held in registers:
  // through the vectors the compiler reloaded every data pointer at each bond end.
  // The sum starts from the ball's accumulator and adds in the same order, so the
  // result is the same to the bit.
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  const std::uint32_t* offset = bonds.ball_offset.data();
  const std::uint32_t* ends = bonds.ball_end.data();
  const std::uint8_t* intact = s.intact.data();
  const std::uint8_t* broke = bonds.broke.data();
  const Vec3* force_b = bonds.force_b.data();
  const Vec3* torque_a = bonds.torque_a.data();
  const Vec3* torque_b = bonds.torque_b.data();
  Vec3* acc_force = scratch.acc_force.data();
  Vec3* acc_torque = scratch.acc_torque.data();
#pragma omp parallel for schedule(static) num_threads(bondTeamSize())
  for (std::ptrdiff_t ii = 0; ii < n; ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    const std::uint32_t first = offset[i], last = offset[i + 1];
    if (first == last) continue;
    Vec3 f = acc_force[i], t = acc_torque[i];
    for (std::uint32_t e = first; e < last; ++e) {
      const std::uint32_t k = ends[e] >> 1;
      if (!intact[k] && !(broke[k] & Bonds::kActs)) continue;
      if (ends[e] & 1u) {
        f += force_b[k];
        t += torque_b[k];
      } else {
        f -= force_b[k];
        t += torque_a[k];
      }
    }
    acc_force[i] = f;
    acc_torque[i] = t;
  }
}

/// The rows of bond ends by ball (ascending bond index in each row), and the
/// per-bond scratch.
void World::Impl::indexBonds() {
  const BondState& s = bonds.state;
  const std::size_t n = p.size();
  bonds.ball_offset.assign(n + 1, 0);
  for (std::size_t k = 0; k < s.size(); ++k) {
    ++bonds.ball_offset[s.a[k] + 1];
    ++bonds.ball_offset[s.b[k] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) bonds.ball_offset[i + 1] += bonds.ball_offset[i];
  bonds.ball_end.assign(2 * s.size(), 0);
  std::vector<std::uint32_t> fill(bonds.ball_offset.begin(), bonds.ball_offset.end() - 1);
  for (std::size_t k = 0; k < s.size(); ++k) {
    bonds.ball_end[fill[s.a[k]]++] = static_cast<std::uint32_t>(2 * k);
    bonds.ball_end[fill[s.b[k]]++] = static_cast<std::uint32_t>(2 * k + 1);
  }
  bonds.force_b.assign(s.size(), Vec3::Zero());
  bonds.torque_a.assign(s.size(), Vec3::Zero());
  bonds.torque_b.assign(s.size(), Vec3::Zero());
  bonds.broke.assign(s.size(), 0);
  bonds.intact = bonds.contact_intact = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!s.intact[k]) continue;
    ++bonds.intact;
    if (s.kind[k] == static_cast<std::uint8_t>(BondKind::Contact)) ++bonds.contact_intact;
  }
  // Only a world with contact bonds hands shear springs to contacts.
  bonds.handover_shear.assign(bonds.contact_intact > 0 ? s.size() : 0, Vec3::Zero());
}

void World::Impl::installBonds(const std::vector<BondSpec>& specs) {
  BondState& s = bonds.state;
  const ParallelBondModel& bm = model.bonds;
  for (const BondSpec& b : specs) {
    const double ra = p.radius[b.a], rb = p.radius[b.b];
    const Vec3 d = p.position[b.b] - p.position[b.a];
    s.a.push_back(b.a);
    s.b.push_back(b.b);
    s.kind.push_back(static_cast<std::uint8_t>(b.kind));
    s.radius.push_back(bm.radius_multiplier * std::min(ra, rb));  // Eq 2-35
    s.tensile_strength.push_back(b.tensile_strength);
    s.shear_strength.push_back(b.shear_strength);
    s.spring_normal.push_back(0.0);
    s.spring_shear.push_back(0.0);
    s.reference_overlap.push_back(0.0);
    s.intact.push_back(1);
    s.normal.push_back(d.norm() > 0 ? Vec3(d.normalized()) : Vec3(Vec3::UnitZ()));
    s.normal_force.push_back(0.0);
    s.shear_force.push_back(Vec3::Zero());
    s.twist_moment.push_back(0.0);
    s.bend_moment.push_back(Vec3::Zero());
    if (b.kind == BondKind::Contact) installContactBond(s.size() - 1);
  }
  indexBonds();
}

/// Elastic energy of the intact bonds: each spring's F^2 / (2 k).
double World::Impl::bondEnergy() const {
  const BondState& s = bonds.state;
  const double kn = model.bonds.normal_stiffness, ks = model.bonds.shear_stiffness;
  double e = 0.0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!s.intact[k]) continue;
    if (s.kind[k] == static_cast<std::uint8_t>(BondKind::Contact)) {
      e += contactBondEnergy(k);
      continue;
    }
    const BondDisc d = bondDisc(s.radius[k]);
    e += 0.5 * s.normal_force[k] * s.normal_force[k] / (kn * d.area);
    e += 0.5 * s.bend_moment[k].squaredNorm() / (kn * d.inertia);
    if (ks > 0) {
      e += 0.5 * s.shear_force[k].squaredNorm() / (ks * d.area);
      e += 0.5 * s.twist_moment[k] * s.twist_moment[k] / (ks * d.polar);
    }
  }
  return e;
}

/// The intact bonds' translational springs for the contact-network step check.
void World::Impl::bondSprings(std::vector<NetworkSpring>& out) const {
  const BondState& s = bonds.state;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!s.intact[k]) continue;
    if (s.kind[k] == static_cast<std::uint8_t>(BondKind::Contact)) {
      out.push_back(contactBondSpring(k));
      continue;
    }
    const BondDisc d = bondDisc(s.radius[k]);
    const std::uint32_t a = s.a[k], b = s.b[k];
    const Vec3 n = s.normal[k];
    NetworkSpring spring;
    spring.a = a;
    spring.b = b;
    spring.normal = n;
    spring.point = bondPoint(p.position[a], p.radius[a], p.radius[b], n,
                             (p.position[b] - p.position[a]).norm());
    spring.kn = model.bonds.normal_stiffness * d.area;
    spring.ks = model.bonds.shear_stiffness * d.area;
    out.push_back(spring);
  }
}

}  // namespace rocklab::sim
