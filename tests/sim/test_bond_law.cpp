// The two-lane bond law (sim/src/stages/bond_law.h) against the one-lane law:
// the bond stage runs two parallel bonds at once when both are intact and one
// by one otherwise, so a bond's bits must not depend on which path took it, or
// a breaking neighbour would change the run. Checked on random bonds, with the
// paths' rare branches (a large spin, a normal that turned over, zero distance,
// a break) in one lane only.
#include <bit>
#include <catch2/catch.hpp>
#include <cstdint>
#include <random>

#include "stages/bond_law.h"

using namespace rocklab::sim::bond_law;
using rocklab::geometry::Vec3;

namespace {

/// One bond's input as the stage reads it, with its balls near touching.
struct RawBond {
  Vec3 xa, xb, va, vb, wa, wb, normal, shear_force, bend_moment;
  double ra, rb, normal_force, twist_moment, radius, tensile_strength, shear_strength;
};

RawBond randomBond(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto vec = [&](double scale) -> Vec3 {  // drawn in a fixed order
    const double x = u(rng), y = u(rng), z = u(rng);
    return Vec3(x, y, z) * scale;
  };
  RawBond b;
  b.ra = 0.0025 * (1.0 + 0.2 * u(rng));
  b.rb = 0.0025 * (1.0 + 0.2 * u(rng));
  b.xa = vec(0.05);
  const double dy = 0.1 * u(rng), dz = 0.1 * u(rng);
  const Vec3 dir = Vec3(1.0, dy, dz).normalized();
  b.xb = b.xa + dir * (b.ra + b.rb + 1e-5 * u(rng));
  b.va = vec(0.5);
  b.vb = vec(0.5);
  b.wa = vec(50.0);
  b.wb = vec(50.0);
  b.normal = (dir + vec(1e-3)).normalized();
  b.shear_force = vec(20.0);
  b.bend_moment = vec(0.02);
  b.normal_force = 50.0 * u(rng);
  b.twist_moment = 0.01 * u(rng);
  b.radius = std::min(b.ra, b.rb);
  b.tensile_strength = 1e9;
  b.shear_strength = 1e9;
  return b;
}

template <class R>
BondInput<R> inputOf(const RawBond* bonds) {
  BondInput<R> in;
  const auto v = [&](auto field) {
    return gather3<R>([&](int l) -> const Vec3& { return bonds[l].*field; });
  };
  const auto s = [&](auto field) { return gather<R>([&](int l) { return bonds[l].*field; }); };
  in.xa = v(&RawBond::xa);
  in.xb = v(&RawBond::xb);
  in.va = v(&RawBond::va);
  in.vb = v(&RawBond::vb);
  in.wa = v(&RawBond::wa);
  in.wb = v(&RawBond::wb);
  in.ra = s(&RawBond::ra);
  in.rb = s(&RawBond::rb);
  in.normal = v(&RawBond::normal);
  in.normal_force = s(&RawBond::normal_force);
  in.shear_force = v(&RawBond::shear_force);
  in.twist_moment = s(&RawBond::twist_moment);
  in.bend_moment = v(&RawBond::bend_moment);
  in.radius = s(&RawBond::radius);
  in.tensile_strength = s(&RawBond::tensile_strength);
  in.shear_strength = s(&RawBond::shear_strength);
  return in;
}

bool sameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
bool sameBits(const Vec3& a, const Vec3& b) {
  return sameBits(a.x(), b.x()) && sameBits(a.y(), b.y()) && sameBits(a.z(), b.z());
}

/// Whether lane `lane` of the pair's output has the one-lane output's bits.
bool laneMatches(const BondOutput<BondPair>& pair, int lane, const BondOutput<double>& one) {
  return sameBits(laneOf(pair.normal, lane), laneOf(one.normal, 0)) &&
         sameBits(laneOf(pair.normal_force, lane), one.normal_force) &&
         sameBits(laneOf(pair.shear_force, lane), laneOf(one.shear_force, 0)) &&
         sameBits(laneOf(pair.twist_moment, lane), one.twist_moment) &&
         sameBits(laneOf(pair.bend_moment, lane), laneOf(one.bend_moment, 0)) &&
         sameBits(laneOf(pair.force_b, lane), laneOf(one.force_b, 0)) &&
         sameBits(laneOf(pair.torque_a, lane), laneOf(one.torque_a, 0)) &&
         sameBits(laneOf(pair.torque_b, lane), laneOf(one.torque_b, 0)) &&
         sameBits(laneOf(pair.tensile, lane), one.tensile) &&
         sameBits(laneOf(pair.shear, lane), one.shear) && laneOf(pair.broke, lane) == one.broke;
}

}  // namespace

TEST_CASE("bond law: two bonds at once give each bond's one-at-a-time bits", "[bonds]") {
  std::mt19937_64 rng(20261207);
  const BondConstants constants{5e12, 2e12, 1e-7, false};
  const BondConstants combined{5e12, 2e12, 1e-7, true};
  int broke = 0, compared = 0;
  for (int trial = 0; trial < 400; ++trial) {
    RawBond bonds[2] = {randomBond(rng), randomBond(rng)};
    const int odd = trial % 2;  // the lane that gets this trial's rare case
    switch (trial % 10) {
      case 1:  // a spin about the bond's axis past the series (2.5e-3 rad in the step)
        bonds[odd].wb = (bonds[odd].xb - bonds[odd].xa).normalized() * 5e4;
        break;
      case 2:
        bonds[odd].normal = -bonds[odd].normal;
        break;  // turned over in one step
      case 3:
        bonds[odd].xb = bonds[odd].xa;
        break;  // no distance: keeps its normal
      case 4:   // breaks in tension
        bonds[odd].tensile_strength = 1e3;
        bonds[odd].normal_force = -10.0;
        break;
      case 5:
        bonds[odd].shear_strength = 1e3;
        break;  // breaks in shear
      default:
        break;
    }
    for (const BondConstants& k : {constants, combined}) {
      const BondOutput<BondPair> pair = stepBond(inputOf<BondPair>(bonds), k);
      for (int lane = 0; lane < 2; ++lane) {
        const BondOutput<double> one = stepBond(inputOf<double>(&bonds[lane]), k);
        CHECK(laneMatches(pair, lane, one));
        broke += one.broke ? 1 : 0;
        ++compared;
      }
    }
  }
  CHECK(compared == 1600);
  // Both rare breaking cases (tension, shear) under both rules, and no other bond.
  CHECK(broke == 4 * 40);
}
