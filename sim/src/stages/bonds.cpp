#include <numbers>
#include <sstream>

#include "../world_impl.h"
#include "bond_law.h"

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
// Threads: the update runs over pairs of bonds (each writes only its own entries), the
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
  BondStress s;  // the bond stage's own arithmetic, so a logged break matches its check
  bond_law::peakStresses(d.radius, d.area, normal_force, shear_force.norm(), std::abs(twist_moment),
                         bend_moment.norm(), s.tensile, s.shear);
  return s;
}

/// Steps the intact parallel bonds k (one or two, the lanes of R) through the
/// bond law and stores their state and forces; a bond that broke is deleted at
/// once (ref §8.2): it carries nothing in the step it breaks, so a pair whose
/// bond breaks at once moves exactly as if never bonded. Returns whether any broke.
template <class R>
bool World::Impl::stepParallelBonds(const std::size_t* k, const bond_law::BondConstants& law) {
  using bond_law::gather;
  using bond_law::gather3;
  using bond_law::laneOf;
  BondState& s = bonds.state;
  const auto a = [&](int lane) { return s.a[k[lane]]; };
  const auto b = [&](int lane) { return s.b[k[lane]]; };
  bond_law::BondInput<R> in;
  in.xa = gather3<R>([&](int l) -> const Vec3& { return p.position[a(l)]; });
  in.xb = gather3<R>([&](int l) -> const Vec3& { return p.position[b(l)]; });
  in.va = gather3<R>([&](int l) -> const Vec3& { return p.velocity[a(l)]; });
  in.vb = gather3<R>([&](int l) -> const Vec3& { return p.velocity[b(l)]; });
  in.wa = gather3<R>([&](int l) -> const Vec3& { return p.omega[a(l)]; });
  in.wb = gather3<R>([&](int l) -> const Vec3& { return p.omega[b(l)]; });
  in.ra = gather<R>([&](int l) { return p.radius[a(l)]; });
  in.rb = gather<R>([&](int l) { return p.radius[b(l)]; });
  in.normal = gather3<R>([&](int l) -> const Vec3& { return s.normal[k[l]]; });
  in.normal_force = gather<R>([&](int l) { return s.normal_force[k[l]]; });
  in.shear_force = gather3<R>([&](int l) -> const Vec3& { return s.shear_force[k[l]]; });
  in.twist_moment = gather<R>([&](int l) { return s.twist_moment[k[l]]; });
  in.bend_moment = gather3<R>([&](int l) -> const Vec3& { return s.bend_moment[k[l]]; });
  in.radius = gather<R>([&](int l) { return s.radius[k[l]]; });
  in.tensile_strength = gather<R>([&](int l) { return s.tensile_strength[k[l]]; });
  in.shear_strength = gather<R>([&](int l) { return s.shear_strength[k[l]]; });
  const bond_law::BondOutput<R> out = bond_law::stepBond(in, law);
  bool any_broke = false;
  for (int lane = 0; lane < bond_law::kLanes<R>; ++lane) {
    const std::size_t j = k[lane];
    s.normal[j] = laneOf(out.normal, lane);
    s.normal_force[j] = laneOf(out.normal_force, lane);
    s.shear_force[j] = laneOf(out.shear_force, lane);
    s.twist_moment[j] = laneOf(out.twist_moment, lane);
    s.bend_moment[j] = laneOf(out.bend_moment, lane);
    if (laneOf(out.broke, lane)) {
      s.intact[j] = 0;
      // The mode is the larger of the two ratios (the only divisions, and only here).
      const double tensile_ratio = laneOf(out.tensile, lane) / s.tensile_strength[j];
      const double shear_ratio = laneOf(out.shear, lane) / s.shear_strength[j];
      bonds.broke[j] = tensile_ratio >= shear_ratio ? Bonds::kTensile : Bonds::kShear;
      bonds.force_b[j].setZero();
      bonds.torque_a[j].setZero();
      bonds.torque_b[j].setZero();
      any_broke = true;
      continue;
    }
    bonds.broke[j] = 0;
    bonds.force_b[j] = laneOf(out.force_b, lane);
    bonds.torque_a[j] = laneOf(out.torque_a, lane);
    bonds.torque_b[j] = laneOf(out.torque_b, lane);
  }
  return any_broke;
}

namespace {

// The step checks merged across threads (mergeChecks: max and or, any order).
#pragma omp declare reduction(mergeStepChecks : StepChecks : mergeChecks(omp_out, omp_in)) \
    initializer(omp_priv = StepChecks{})

}  // namespace

void World::Impl::bondStage(StepChecks& checks) {
  BondState& s = bonds.state;
  const ParallelBondModel& bm = model.bonds;
  const bond_law::BondConstants law{bm.normal_stiffness, bm.shear_stiffness, dt,
                                    bm.failure_rule == BondFailureRule::Combined};
  // Bonds go in pairs, two parallel bonds at once through the two-lane law
  // (bond_law.h: the same bits as one at a time); a pair with a contact bond or
  // a broken bond goes one by one.
  const auto npairs = static_cast<std::ptrdiff_t>((s.size() + 1) / 2);
  constexpr auto kContact = static_cast<std::uint8_t>(BondKind::Contact);
  const auto isIntactParallel = [&](std::size_t k) { return s.intact[k] && s.kind[k] != kContact; };
  bool any_broke = false;
  StepChecks bonded;  // the overlaps of contact-bonded pairs
  // clang-format off
#pragma omp parallel for schedule(static) num_threads(bondTeamSize()) \
    reduction(|| : any_broke) reduction(mergeStepChecks : bonded)
  // clang-format on
  for (std::ptrdiff_t jj = 0; jj < npairs; ++jj) {
    const std::size_t k0 = 2 * static_cast<std::size_t>(jj), k1 = k0 + 1;
    if (k1 < s.size() && isIntactParallel(k0) && isIntactParallel(k1)) {
      const std::size_t both[2] = {k0, k1};
      any_broke |= stepParallelBonds<bond_law::BondPair>(both, law);
      continue;
    }
    for (const std::size_t k : {k0, k1}) {
      if (k >= s.size()) break;
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
      const std::size_t one[1] = {k};
      any_broke |= stepParallelBonds<double>(one, law);
    }
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
