#pragma once
// The population-balance breakage of the PBM cone crusher (experiments.md §g.6):
// the strength of a ball, drawn once per ball id, and the fragments that replace a
// ball that breaks. Pure functions; the crusher driver applies them
// (drivers/crusher_breakage.h) and the freeze relaxes the fragments
// (crusher/breakage_freeze.h).
#include <cstdint>
#include <string>
#include <vector>

#include "rocklab/geometry/vec.h"

namespace rocklab::experiments::crusher {

/// Weibull strength with a size effect (§g.6, Eq 6-13):
/// q_strength = q0(d) (-ln U)^(1/m), q0(d) = q_ref (d / d_ref)^b. The defaults are
/// the reference's recommended reading [I]: 25.2 MPa belongs to d = 21 mm, the middle
/// of the 14-28 mm feed (it reproduces the quoted end values within 2 %).
struct StrengthLaw {
  double q_ref = 25.2e6;          // Pa, 37 % octahedral strength at d_ref
  double d_ref = 0.021;           // m
  double size_exponent = -1.1;    // b
  double weibull_modulus = 2.65;  // m
  /// q0(d), Pa: 37 % of the balls of diameter d are stronger.
  double scale(double diameter) const;
  /// The strength of a ball of diameter d whose uniform draw is u in (0, 1), Pa.
  double strength(double diameter, double u) const;
};

/// A uniform number in (0, 1) for ball `id` of a run with `seed`: a counter-based
/// hash (splitmix64 of the seed and the id), not a running generator, so a ball's
/// strength does not depend on the thread count, on the order in which balls were
/// checked or broke, or on a restart.
double uniformFromId(std::uint64_t seed, std::uint64_t id);

enum class SplitMode {
  Triple,  // 60 / 30 / 10 % of the mass (the studies' default)
  Equal,   // two halves
};

/// The scene's name of `mode` (experiment.breakage.mode).
inline const char* modeName(SplitMode mode) { return mode == SplitMode::Triple ? "triple" : "equal"; }

/// Mass fractions of the fragments of `mode`, in the order of their offsets.
std::vector<double> massFractions(SplitMode mode);
/// The reference's [X] placement, in parent radii along the minor principal
/// direction: triple: the 60 % and 30 % spheres internally tangent at opposite
/// ends (-(1 - 0.6^(1/3)) = -0.157, +(1 - 0.3^(1/3)) = +0.331), the 10 % at the
/// centre; equal: both halves internally tangent (-/+ (1 - 0.5^(1/3)) = 0.206).
std::vector<double> defaultOffsets(SplitMode mode);
/// "" or why `offsets` (parent radii) do not fit `mode`: one per fragment, every
/// fragment inside the parent (|offset| + its radius ratio <= 1).
std::string offsetsProblem(SplitMode mode, const std::vector<double>& offsets);

struct FragmentBall {
  geometry::Vec3 position = geometry::Vec3::Zero();  // m
  double radius = 0.0;                               // m
  double mass = 0.0;                                 // kg
};

/// The fragments replacing a ball of `radius` and `mass` at `centre`: masses the
/// fractions of `mode` (the last one the remainder, so they add up to the parent's
/// mass to round-off), radii R (m_f / m)^(1/3) (the parent's density), centres at
/// centre + offset R `direction` (direction: unit, the minor principal stress).
std::vector<FragmentBall> splitBall(const geometry::Vec3& centre, double radius, double mass,
                                    const geometry::Vec3& direction, SplitMode mode,
                                    const std::vector<double>& offsets);

}  // namespace rocklab::experiments::crusher
