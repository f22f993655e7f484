#include "agglomerate/servo_pack.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "agglomerate/servo_wall.h"
#include "rocklab/sim/world.h"

namespace rocklab::experiments::agglomerate {

namespace {

using geometry::Vec3;

constexpr int kPlacementAttempts = 10000;  // per sphere

// `count` centres drawn uniformly (seeded) in the sphere of `container` radius at
// the origin, each sphere of `radius` wholly inside it and overlapping none placed
// before (random sequential addition; loose, so it never jams).
std::vector<Vec3> randomCentres(std::size_t count, double radius, double container,
                                std::uint64_t seed) {
  geometry::Rng rng(seed);
  const double reach = container - radius, min_dist2 = 4.0 * radius * radius;
  std::vector<Vec3> centres;
  centres.reserve(count);
  for (std::size_t n = 0; n < count; ++n) {
    bool placed = false;
    for (int attempt = 0; attempt < kPlacementAttempts && !placed; ++attempt) {
      const Vec3 x(rng.uniform(-reach, reach), rng.uniform(-reach, reach),
                   rng.uniform(-reach, reach));
      if (x.squaredNorm() > reach * reach) continue;
      placed = true;
      for (const Vec3& c : centres)
        if ((c - x).squaredNorm() < min_dist2) {
          placed = false;
          break;
        }
      if (placed) centres.push_back(x);
    }
    if (!placed)
      throw PackingError("servo pack: could not place sphere " + std::to_string(n + 1) + " of " +
                         std::to_string(count) + " at random (initial solid fraction too high)");
  }
  return centres;
}

sim::Model compactionModel(const ServoPackParams& p) {
  sim::Model model;
  sim::Material rock;
  rock.name = "rock";
  rock.density = p.material.density;
  rock.shear_modulus = p.material.shear_modulus;
  rock.poisson = p.material.poisson;
  rock.friction = p.material.friction;
  model.materials.push_back(rock);
  model.contact.law = sim::ContactLaw::HertzMindlin;
  model.contact.local_damping = p.material.local_damping;
  model.contact.damping_normal = p.material.contact_damping;
  model.gravity = Vec3::Zero();
  // Hertz step audit at the fastest impact expected: the wall's top speed (with the
  // damping below a struck ball does not rebound faster than the wall closes).
  model.timestep.impact_velocity = p.max_speed;
  // The wall does work on the pack that the energy check cannot see (it counts only
  // the engine's moving walls): off here. The overlap and step checks stay on.
  model.watchdog.max_energy_growth = 0.0;
  return model;
}

}  // namespace

ServoPackResult servoCompactedPack(const ServoPackParams& p) {
  if (p.count < 1) throw std::invalid_argument("servo pack: count must be >= 1");
  if (!(p.radius > 0)) throw std::invalid_argument("servo pack: radius must be > 0");
  if (!(p.initial_solid_fraction > 0 && p.initial_solid_fraction < 0.35))
    throw std::invalid_argument("servo pack: initial_solid_fraction must be in (0, 0.35)");
  const auto t0 = std::chrono::steady_clock::now();

  ServoPackResult result;
  // The centres' sphere (radius R0 - r) holds the solid fraction, so that small packs,
  // where the wall takes much of the volume, place as easily as large ones.
  result.initial_wall_radius =
      p.radius * (1.0 + std::cbrt(static_cast<double>(p.count) / p.initial_solid_fraction));
  std::vector<sim::SphereSpec> balls;
  for (const Vec3& x : randomCentres(p.count, p.radius, result.initial_wall_radius, p.seed)) {
    sim::SphereSpec s;
    s.position = x;
    s.radius = p.radius;
    balls.push_back(s);
  }

  ServoWallSettings ws;
  ws.initial_radius = result.initial_wall_radius;
  ws.target_pressure = p.target_pressure;
  ws.max_speed = p.max_speed;
  ws.shear_modulus = p.material.shear_modulus;
  ws.poisson = p.material.poisson;
  auto wall = std::make_shared<ServoWall>(ws);
  sim::World world(compactionModel(p), balls, 1);
  world.addForceContribution(wall);

  // Phase 1 with the central body force (see the header), phase 2 without it.
  // a = p_target / (rho phi R): the weight of a column from the centre to the wall.
  const double expected_radius = p.radius * std::cbrt(static_cast<double>(p.count) / 0.6);
  const double central = p.precompact_interior
                             ? p.target_pressure / (p.material.density * 0.6 * expected_radius)
                             : 0.0;
  bool first_phase = central > 0, done = false;
  wall->setCentralAcceleration(central);
  sim::Energy energy;
  auto observe = [&](const sim::Snapshot& s) {
    energy = s.energy;
    const double kinetic = energy.kinetic_translational + energy.kinetic_rotational;
    const double stored = energy.elastic + energy.potential_other;
    const double fraction = first_phase ? p.first_phase_kinetic_fraction : p.kinetic_fraction;
    done =
        std::abs(wall->pressure() - p.target_pressure) < p.pressure_tolerance * p.target_pressure &&
        kinetic < fraction * stored;
  };
  const auto interval = static_cast<std::uint64_t>(std::max(1, p.check_interval));
  while (world.stepCount() < p.max_steps) {
    if (done && !first_phase) break;
    if (done) {
      first_phase = done = false;
      wall->setCentralAcceleration(0.0);
      result.first_phase_steps = world.stepCount();
    }
    if ((world.stepCount() + 1) % interval == 0)
      world.step(observe);
    else
      world.step();
  }
  done = done && !first_phase;
  result.kinetic_energy = energy.kinetic_translational + energy.kinetic_rotational;
  result.elastic_energy = energy.elastic + energy.potential_other;
  result.pressure = wall->pressure();
  if (!done) {
    std::ostringstream s;
    s << "servo pack of " << p.count << " spheres (seed " << p.seed << "): not at rest at "
      << p.target_pressure << " Pa after " << p.max_steps << " steps: wall pressure "
      << result.pressure << " Pa (needs to be within " << 100 * p.pressure_tolerance
      << " %), kinetic energy " << result.kinetic_energy << " J (needs < " << p.kinetic_fraction
      << " x stored " << result.elastic_energy << " J); try --pack geometric";
    throw PackingError(s.str());
  }
  result.wall_radius = wall->radius();
  result.wall_contacts = wall->contacts();
  result.max_wall_penetration = wall->maxPenetration();
  result.steps = world.stepCount();
  result.dt = world.dt();
  const sim::ParticleState& particles = world.particles();
  for (std::size_t i = 0; i < particles.size(); ++i)
    result.spheres.push_back({particles.position[i], particles.radius[i]});
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace rocklab::experiments::agglomerate
