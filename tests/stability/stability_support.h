#pragma once
// Helpers of the stability suite (issue 8): small worlds at the study's sizes,
// a runner that records what a case needs to be judged (non-finite state, the
// largest overlap, the energy history, the watchdog's message and step), and a
// one-line figure per case for docs/stability.md.
//
// Every case ends in one of two ways and asserts which: it runs stably (finite,
// energy bounded with no work input, overlaps below a stated fraction), or the
// watchdog stops it with its message at a step the test states. Never garbage.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "rocklab/sim/world.h"
#include "support/sim_builders.h"

namespace rocklab::stab {

using geometry::Vec3;
using test::plane;
using test::sphere;

constexpr double kRock = 0.014;      // m, radius of a 28 mm rock (the crusher feed)
constexpr double kFragment = 0.002;  // m, radius of a 4 mm fragment (smallest breakable size)
constexpr double kDensity = 2730.0;  // kg/m^3, the study's pebbles

inline double sphereMass(double r, double rho = kDensity) {
  return rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

/// Materials: 0 = "ball", 1 = "wall"; linear law with the given *pair*
/// stiffness (each material gets 2k so that the series value is k), no gravity.
inline sim::Model linearPair(double k_pair, double friction = 0.37, double beta = 0.0) {
  sim::Model m;
  m.materials = {sim::Material{"ball", kDensity, 2 * k_pair, 2 * k_pair, friction, 0.0, 0.2},
                 sim::Material{"wall", 7800.0, 2 * k_pair, 2 * k_pair, friction, 0.0, 0.2}};
  m.contact.damping_normal = m.contact.damping_shear = beta;
  m.gravity = Vec3::Zero();
  return m;
}

/// Hertz–Mindlin with shear modulus G for balls and walls, no gravity.
inline sim::Model hertz(double shear_modulus, double friction = 0.37, double beta = 0.0) {
  sim::Model m;
  m.contact.law = sim::ContactLaw::HertzMindlin;
  m.materials = {sim::Material{"ball", kDensity, 0, 0, friction, shear_modulus, 0.2},
                 sim::Material{"wall", 7800.0, 0, 0, friction, shear_modulus, 0.2}};
  m.contact.damping_normal = m.contact.damping_shear = beta;
  m.gravity = Vec3::Zero();
  return m;
}

/// Square polygon of half side `half` centred at `c`, facing +z.
inline sim::Wall squareZ(const std::string& name, Vec3 c, double half, int material = 1) {
  sim::Wall w;
  w.name = name;
  w.shape = sim::WallShape::Polygon;
  w.vertices = {c + Vec3(-half, -half, 0), c + Vec3(half, -half, 0), c + Vec3(half, half, 0),
                c + Vec3(-half, half, 0)};
  w.material = material;
  return w;
}

/// Largest overlap / smaller radius over ball pairs (members of one clump
/// excluded) and static plane walls, by brute force (small worlds only).
inline double maxOverlapFraction(const sim::World& w) {
  const sim::ParticleState& p = w.particles();
  double worst = 0.0;
  const bool clumps = !p.clump.empty();
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      if (clumps && p.clump[i] >= 0 && p.clump[i] == p.clump[j]) continue;
      const double d = (p.position[j] - p.position[i]).norm();
      const double ov = p.radius[i] + p.radius[j] - d;
      if (ov > 0) worst = std::max(worst, ov / std::min(p.radius[i], p.radius[j]));
    }
    for (const sim::Wall& wall : w.model().walls) {
      if (wall.shape != sim::WallShape::Plane || !wall.motion.isStatic()) continue;
      const double ov = p.radius[i] - (p.position[i] - wall.point).dot(wall.normal.normalized());
      if (ov > 0) worst = std::max(worst, ov / p.radius[i]);
    }
  }
  return worst;
}

/// What a run did.
struct Outcome {
  bool stopped = false;         // the watchdog threw
  std::string message;          // its message
  std::uint64_t steps = 0;      // steps completed (the step the watchdog fired at when stopped)
  bool finite = true;           // every position, velocity and spin finite at the end
  double max_overlap = 0.0;     // largest overlap / smaller radius seen (observed steps)
  double e_first = 0.0;         // J, total mechanical energy at the first observed step
  double e_max = -1e300;        // J, largest total seen
  double e_min = 1e300;         // J, smallest total seen
  double e_last = 0.0;          // J, at the last observed step
  double ke_last = 0.0;         // J, kinetic energy at the last observed step
  double max_speed = 0.0;       // m/s, fastest ball seen (observed steps)
  bool any_observed = false;
};

inline bool allFinite(const sim::World& w) {
  const sim::ParticleState& p = w.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!p.position[i].allFinite() || !p.velocity[i].allFinite() || !p.omega[i].allFinite()) return false;
  return true;
}

/// Steps `w` up to `steps` times (or until `stop` says so after an observed
/// step), observing every `every` steps: energy, overlap, speed. A watchdog
/// error ends the run and is recorded, never rethrown.
inline Outcome run(sim::World& w, std::uint64_t steps, std::uint64_t every = 1,
                   const std::function<bool(const sim::Snapshot&)>& stop = {},
                   bool overlaps = true) {
  Outcome o;
  bool want_stop = false;
  auto observe = [&](const sim::Snapshot& s) {
    const double e = s.energy.total();
    if (!o.any_observed) o.e_first = e;
    o.any_observed = true;
    o.e_max = std::max(o.e_max, e);
    o.e_min = std::min(o.e_min, e);
    o.e_last = e;
    o.ke_last = s.energy.kinetic_translational + s.energy.kinetic_rotational;
    for (const Vec3& v : s.velocity) o.max_speed = std::max(o.max_speed, v.norm());
    if (stop && stop(s)) want_stop = true;
  };
  const std::function<void(const sim::Snapshot&)> obs = observe;
  try {
    for (std::uint64_t k = 0; k < steps && !want_stop; ++k) {
      const bool due = k % every == 0;
      w.step(due ? obs : std::function<void(const sim::Snapshot&)>{});
      if (due && overlaps) o.max_overlap = std::max(o.max_overlap, maxOverlapFraction(w));
      o.steps = k + 1;
    }
  } catch (const sim::WatchdogError& e) {
    o.stopped = true;
    o.message = e.what();
    o.steps = w.stepCount();
  }
  o.finite = allFinite(w);
  return o;
}

/// Largest |e - 1| (e = speed out / speed in) of an undamped linear impact
/// integrated by the leapfrog at omega dt, over where the touch falls between
/// two steps. The integrator's own error, not the model's: the force switches on
/// at the first step inside, so the contact's phase error depends on that offset
/// and is not monotone in the step (at omega dt = 0.358: +-1.3 %, at 0.447:
/// +-0.3 %). Dimensionless recurrence: X = x / (v dt), V = v' / v.
inline double leapfrogImpactError(double omega_dt) {
  double worst = 0.0;
  for (int k = 0; k < 400; ++k) {
    double x = 3.0 + k / 400.0, v = -1.0;
    bool inside = false;
    for (int n = 0; n < 100000; ++n) {
      if (x < 0) v -= omega_dt * omega_dt * x;
      x += v;
      inside = inside || x < 0;
      if (inside && x >= 0 && v > 0) break;
    }
    worst = std::max(worst, std::abs(v - 1.0));
  }
  return worst;
}

/// One line per case for docs/stability.md: `stability-figure | name | text`.
/// Printed to stdout (ctest -V, or the binary run directly).
inline void figure(const std::string& name, const std::string& text) {
  std::cout << "stability-figure | " << name << " | " << text << "\n" << std::flush;
}

inline std::string num(double x, int precision = 3) {
  std::ostringstream s;
  s.precision(precision);
  s << x;
  return s.str();
}

}  // namespace rocklab::stab
