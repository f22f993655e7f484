#pragma once
// The loose pack of equal spheres of r_max that fills a sphere of the agglomerate's
// diameter (experiments.md §f.4 step 1 and its [X]: the study gives neither the
// sphere count nor the initial wall radius).
//   servo:     the DEM compaction (servo_pack.h). The count is found so that the
//              wall stops at the agglomerate's radius R: a first guess from a solid
//              fraction (kServoSolidFraction), then corrected with the measured wall
//              radius, N' = N ((R - band/2) / R_w)^3, until R - band <= R_w <= R
//              (band = kRadiusBand R), at most kMaxCountTrials packs; else the trial
//              with the largest R_w <= R is kept (or the tightest one).
//   geometric: relaxedRandomPack (geometry/random_pack.h), the geometric stand-in:
//              no forces, the count from kGeometricSolidFraction, the container = R.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "agglomerate/servo_pack.h"

namespace rocklab::experiments::agglomerate {

enum class PackKind { Servo, Geometric };
PackKind parsePackKind(const std::string& name);  // "servo" | "geometric"; invalid_argument
const char* packKindName(PackKind kind);

inline constexpr double kServoSolidFraction = 0.57;      // first guess of the count
inline constexpr double kGeometricSolidFraction = 0.56;  // relaxedRandomPack converges below ~0.6
inline constexpr double kRadiusBand = 0.02;              // of R: accepted wall radii
inline constexpr int kMaxCountTrials = 4;

struct LoosePackParams {
  PackKind kind = PackKind::Servo;
  double diameter = 0.05;  // m  of the agglomerate
  std::uint64_t seed = 1;
  std::size_t first_count = 0;  // first trial count (0 = from the solid fraction)
  ServoPackParams servo;        // count and seed are set here; radius = r_max
};

struct PackTrial {
  std::size_t count = 0;
  double wall_radius = 0.0;  // m
  std::uint64_t steps = 0;
  double wall_time_s = 0.0;
};

struct LoosePack {
  std::vector<geometry::Sphere> spheres;  // about the origin
  std::size_t count = 0;
  double container_radius = 0.0;  // m  the wall's final radius (servo) or R (geometric)
  double pressure = 0.0;          // Pa  servo only
  std::uint64_t steps = 0;        // DEM steps of the kept pack (servo)
  double dt = 0.0;                // s
  std::vector<PackTrial> trials;  // in order (one for geometric)
  double wall_time_s = 0.0;       // all trials
};

/// Throws std::invalid_argument for a diameter below 2 r_max, PackingError as the
/// servo pack does.
LoosePack loosePackForDiameter(const LoosePackParams& params);

}  // namespace rocklab::experiments::agglomerate
