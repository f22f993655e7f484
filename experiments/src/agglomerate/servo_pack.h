#pragma once
// The loose pack of equal spheres compacted by the DEM engine inside a servo-
// controlled spherical wall (experiments.md §f.4 step 1): `count` spheres of r_max
// placed at random (seeded, not overlapping) in a sphere loose enough to place
// them, then the wall (servo_wall.h) closes until the pack carries the target
// pressure at rest. Hertz-Mindlin contacts with the Table 5.2 material, local
// damping, no gravity.
//
// Two phases. Without help, the outermost layer, ordered against the smooth wall,
// becomes a shell that carries the wall pressure by hoop compression, and the
// interior stays unloaded and looser (measured, 50 mm: every overlap below 1e-8 m
// inside r/R < 0.83, all the locked-in stress in the outer 4 mm). So phase 1 adds a
// body force pulling every ball towards the centre, of acceleration
// a = p_target / (rho phi R) (phi = 0.6, R from the count: the weight of a column
// from the centre to the wall is the target), which compacts the interior as well;
// phase 2 removes it and lets the pack settle under the wall alone (measured: mean
// overlap 6e-7 m at every radius, coordination of the r0 = 1 pack 5.2 instead of 3.7).
//
// Each phase is done when both hold at a check (every check_interval steps):
//   |p - p_target| < pressure_tolerance p_target  (p the wall's measured pressure), and
//   kinetic energy < kinetic_fraction x the elastic energy stored in the contacts
//   (ball-ball and ball-wall): the pack is at rest relative to its own loading
//   (first_phase_kinetic_fraction in phase 1: it only has to be compact).
// Otherwise PackingError after max_steps.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::experiments::agglomerate {

/// A pack that could not be made (step budget spent, impossible count).
struct PackingError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The balls' material and contact model of the compaction (Table 5.2).
struct PackMaterial {
  double density = 2700.0;      // kg/m^3
  double shear_modulus = 70e9;  // Pa  G (Table 5.2 read literally, see experiments.md §f.1)
  double poisson = 0.2;         // -
  // -  during compaction only: frictionless spheres reach a dense random pack (the
  // bonds later take the friction of Table 5.2, 0.5, from the scene).
  double friction = 0.0;
  double local_damping = 0.7;  // -  alpha of Eq 2-15
  // -  beta_n of the contact dashpot (Eq 2-17), compaction only: local damping acts on
  // the net force, so it leaves the rattlers of a frictionless pack (balls with no
  // load) bouncing in their cages; this dashpot takes their energy at every hit. The
  // 50 mm pack came to rest in ~60k steps with it, ~170k without.
  double contact_damping = 0.3;
};

struct ServoPackParams {
  std::size_t count = 0;                 // spheres
  double radius = 0.0;                   // m  r_max
  std::uint64_t seed = 1;                // random placement
  double initial_solid_fraction = 0.25;  // -  of the random placement (wall radius at start)
  double target_pressure = 1e5;          // Pa
  double pressure_tolerance = 0.01;      // -  of the target
  double kinetic_fraction = 1e-3;        // -  of the stored elastic energy
  double max_speed = 1.0;                // m/s  of the wall
  std::uint64_t max_steps = 400000;
  bool precompact_interior = true;             // phase 1 (above)
  double first_phase_kinetic_fraction = 1e-2;  // -
  int check_interval = 100;                    // steps
  PackMaterial material;
};

struct ServoPackResult {
  std::vector<geometry::Sphere> spheres;  // centres about the wall's centre (the origin)
  double wall_radius = 0.0;               // m  at the end
  double pressure = 0.0;                  // Pa  measured at the end
  double kinetic_energy = 0.0;            // J
  double elastic_energy = 0.0;            // J  contacts and wall
  double initial_wall_radius = 0.0;       // m
  double max_wall_penetration = 0.0;      // m
  std::size_t wall_contacts = 0;
  std::uint64_t steps = 0;
  std::uint64_t first_phase_steps = 0;  // of `steps`
  double dt = 0.0;                      // s
  double wall_time_s = 0.0;             // s
};

/// Throws std::invalid_argument for count < 1 or radius <= 0, PackingError when the
/// pack is not at the target after max_steps.
ServoPackResult servoCompactedPack(const ServoPackParams& params);

}  // namespace rocklab::experiments::agglomerate
