#pragma once
// Bonds between balls, of two kinds in one per-bond table (BondState::kind):
//
// Parallel bonds (dem-models.md §8.2, Eq 2-27..2-38 with the [R] corrections):
// a disc of elastic cement of radius R = phi min(R_A, R_B) between two balls,
// in parallel with their ordinary contact, carrying a force and a moment. The
// bond stage of World::step (src/stages/bonds.cpp) updates every intact bond
// from the relative motion of its balls and adds its force and moment into
// their accumulators; a bond whose peak stress reaches its strength breaks for
// good, and the pair keeps only its ordinary frictional contact. A world
// without bonds skips the stage and pays nothing.
//
// Contact bonds (§8.1): a zero-size glue point at the contact, a normal and a
// shear spring with strengths F_c^n and F_c^s in N (forces, not stresses).
// While intact it replaces the pair's ordinary contact (the pair is kept out of
// the neighbour list): tension is allowed and the contact cannot slip. Its
// springs are the pair's contact stiffnesses (linear law: K^n, K^s of Eq 2-20,
// 2-21; Hertz: the tangent stiffnesses of Eq 2-22, 2-23 at the bonding overlap,
// which must be > 0), linear while intact; the normal one is unstressed at the
// reference overlap (linear law: 0, or the gap at bonding; so an overlapping
// pair keeps its contact force), the shear one incremental with no Coulomb cap.
// The contact dashpots act as on any sticking contact. Breakage (§8.1): tension
// -F_n >= F_c^n: both forces zero at once; |F_s| >= F_c^s: the ordinary contact
// takes over in the same step from the bond's shear spring, so the forces are
// kept when the contact is compressive and within the friction limit, else the
// slip and no-tension rules cut them. A parallel bond may join the same pair.
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

/// What a bond is (BondState::kind, BondSpec::kind).
enum class BondKind : std::uint8_t {
  Parallel = 0,  // §8.2: a cement disc beside the contact (force and moment)
  Contact = 1,   // §8.1: a glue point at the contact (normal and shear spring)
};
const char* bondKindName(BondKind kind);  // "parallel", "contact"

/// A bond to install between balls a and b (indices into the world's balls:
/// the spheres first, then clump members). A parallel bond is installed
/// stress-free at the configuration the world starts from; a contact bond
/// carries the pair's contact force there (none when the pair has a gap).
struct BondSpec {
  std::uint32_t a = 0, b = 0;
  // Parallel: Pa (sigma_c, tau_c, peak stresses); contact: N (F_c^n, F_c^s).
  double tensile_strength = std::numeric_limits<double>::infinity();
  double shear_strength = std::numeric_limits<double>::infinity();
  BondKind kind = BondKind::Parallel;
};

// X(type, name, unit, meaning) for every per-bond array: the struct, removal
// (withoutBalls), the checkpoint's size check, write and read expand it.
// Fields marked "contact" are 0 for parallel bonds; twist and bend 0 for contact bonds.
#define ROCKLAB_BOND_FIELDS(X)                                                 \
  X(std::uint32_t, a, "", "first ball (index)")                                \
  X(std::uint32_t, b, "", "second ball (index); n points from a to b")         \
  X(std::uint8_t, kind, "", "BondKind: 0 parallel (§8.2), 1 contact (§8.1)")   \
  X(double, radius, "m", "R of Eq 2-35 (contact bonds: 0, zero size)")         \
  X(double, tensile_strength, "Pa | N", "sigma_c (parallel) | F_c^n (contact)") \
  X(double, shear_strength, "Pa | N", "tau_c (parallel) | F_c^s (contact)")    \
  X(double, spring_normal, "N/m", "contact: normal spring")                    \
  X(double, spring_shear, "N/m", "contact: shear spring")                      \
  X(double, reference_overlap, "m", "contact: overlap of zero normal force")   \
  X(std::uint8_t, intact, "", "1 until the bond breaks (then for ever 0)")     \
  X(geometry::Vec3, normal, "",                                               \
    "unit, a -> b, at the last update (the frame of the vectors below)")      \
  X(double, normal_force, "N", "on b along n, compression > 0 (Eq 2-29; contact: spring)") \
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
  BondKind kind = BondKind::Parallel;
  BondFailureMode mode = BondFailureMode::Tensile;
  double tensile_stress = 0.0;  // Pa  sigma_max of Eq 2-33 at breakage (contact bonds: 0)
  double shear_stress = 0.0;    // Pa  tau_max of Eq 2-34 at breakage (contact bonds: 0)
  double normal_force = 0.0;    // N   the bond's normal force at breakage, compression > 0
  double shear_force = 0.0;     // N   |F_s| of the bond at breakage
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
