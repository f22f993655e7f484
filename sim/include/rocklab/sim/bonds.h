#pragma once
// Parallel bonds (dem-models.md §8.2, Eq 2-27..2-38 with the [R] corrections):
// a disc of elastic cement of radius R = phi min(R_A, R_B) between two balls,
// in parallel with their ordinary contact, carrying a force and a moment. The
// bond stage of World::step (src/stages/bonds.cpp) updates every intact bond
// from the relative motion of its balls and adds its force and moment into
// their accumulators; a bond whose peak stress reaches its strength breaks for
// good, and the pair keeps only its ordinary frictional contact. A world
// without bonds skips the stage and pays nothing.
//
// Sign convention (the reference's, [X] of §8.2): n points from A to B; the
// force and moment are those the bond exerts on B; the normal force is positive
// in compression, so separation builds tension (negative normal force) and the
// peak tensile stress of Eq 2-33 is then positive.
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim {

/// When a bond breaks.
enum class BondFailureRule {
  // The reference's rule: sigma_max >= sigma_c or tau_max >= tau_c (Eq 2-33, 2-34).
  Stress,
  // The sum of the four force/moment ratios reaches 1: tension/(sigma_c A) +
  // |M_s| R/(sigma_c I) + |F_s|/(tau_c A) + |M_n| R/(tau_c J) >= 1 (as some other
  // codes do; for comparisons).
  Combined,
};

/// Constants of every parallel bond of a model.
struct ParallelBondModel {
  double radius_multiplier = 1.0;  // -     phi of Eq 2-35 (the study: 1)
  // Stiffnesses per unit area (stress per displacement): the study's 5e12 and
  // 2e12 are printed "N/m", [I] of §8.2: the unit is N/m^3 = Pa/m.
  double normal_stiffness = 0.0;  // Pa/m  k_n of Eq 2-29, 2-32
  double shear_stiffness = 0.0;   // Pa/m  k_s of Eq 2-30, 2-31
  BondFailureRule failure_rule = BondFailureRule::Stress;
};

/// A bond to install between balls a and b (indices into the world's balls:
/// the spheres first, then clump members). Installed stress-free at the
/// configuration the world starts from.
struct BondSpec {
  std::uint32_t a = 0, b = 0;
  double tensile_strength = std::numeric_limits<double>::infinity();  // Pa  sigma_c
  double shear_strength = std::numeric_limits<double>::infinity();    // Pa  tau_c
};

// X(type, name, unit, meaning) for every per-bond array: the struct, removal
// (withoutBalls), the checkpoint's size check, write and read expand it.
#define ROCKLAB_BOND_FIELDS(X)                                                \
  X(std::uint32_t, a, "", "first ball (index)")                               \
  X(std::uint32_t, b, "", "second ball (index); n points from a to b")        \
  X(double, radius, "m", "R of Eq 2-35")                                      \
  X(double, tensile_strength, "Pa", "sigma_c")                                \
  X(double, shear_strength, "Pa", "tau_c")                                    \
  X(std::uint8_t, intact, "", "1 until the bond breaks (then for ever 0)")    \
  X(geometry::Vec3, normal, "",                                               \
    "unit, a -> b, at the last update (the frame of the vectors below)")      \
  X(double, normal_force, "N", "on b along n, compression > 0 (Eq 2-29)")     \
  X(geometry::Vec3, shear_force, "N", "on b, in the contact plane (Eq 2-30)") \
  X(double, twist_moment, "N m", "on b about n (Eq 2-31)")                    \
  X(geometry::Vec3, bend_moment, "N m", "on b, in the contact plane (Eq 2-32)")

#define ROCKLAB_DECLARE_BOND_FIELD(type, name, unit, meaning) std::vector<type> name;
/// Every bond of a world, intact and broken (a broken bond keeps its index, so
/// event logs and outputs refer to one numbering for the whole run).
struct BondState {
  ROCKLAB_BOND_FIELDS(ROCKLAB_DECLARE_BOND_FIELD)
  std::size_t size() const { return a.size(); }
};
#undef ROCKLAB_DECLARE_BOND_FIELD

enum class BondFailureMode { Tensile, Shear };
const char* bondFailureModeName(BondFailureMode mode);  // "tensile", "shear"

/// One breakage, as the bond stage saw it in the step it broke.
struct BondBreak {
  double time = 0.0;  // s
  std::uint64_t step = 0;
  std::uint32_t bond = 0, a = 0, b = 0;
  BondFailureMode mode = BondFailureMode::Tensile;
  double tensile_stress = 0.0;  // Pa  sigma_max of Eq 2-33 at breakage
  double shear_stress = 0.0;    // Pa  tau_max of Eq 2-34 at breakage
};

/// The disc of one bond: area and moments (Eq 2-36..2-38).
struct BondDisc {
  double radius = 0.0;   // m
  double area = 0.0;     // m^2   A = pi R^2
  double polar = 0.0;    // m^4   J = pi R^4 / 2
  double inertia = 0.0;  // m^4   I = pi R^4 / 4
};
BondDisc bondDisc(double radius);

/// Peak stresses on the periphery of a bond (Eq 2-33, 2-34).
struct BondStress {
  double tensile = 0.0;  // Pa  sigma_max = -F_n / A + |M_s| R / I
  double shear = 0.0;    // Pa  tau_max = |F_s| / A + |M_n| R / J
};
BondStress bondStress(const BondDisc& disc, double normal_force, const geometry::Vec3& shear_force,
                      double twist_moment, const geometry::Vec3& bend_moment);

/// Fragments: the balls joined by intact bonds (directly or through others).
/// Returns one label per ball, 0, 1, 2, ... in the order of each fragment's
/// lowest ball index; an unbonded ball is a fragment of its own.
std::vector<std::uint32_t> bondedClusters(std::size_t ball_count, const BondState& bonds);
/// The same from the bond arrays alone (a Snapshot's bond_a, bond_b, bond_intact).
std::vector<std::uint32_t> bondedClusters(std::size_t ball_count, std::span<const std::uint32_t> a,
                                          std::span<const std::uint32_t> b,
                                          std::span<const std::uint8_t> intact);

}  // namespace rocklab::sim
