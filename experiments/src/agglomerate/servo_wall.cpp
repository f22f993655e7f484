#include "agglomerate/servo_wall.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "rocklab/sim/timestep.h"  // hertzCoefficient (Eq 2-22)

namespace rocklab::experiments::agglomerate {

namespace {
// Penetration of ball i into the wall (m, > 0 when touching) and the outward unit
// normal at the ball.
struct WallTouch {
  double penetration = 0.0;
  sim::Vec3 normal = sim::Vec3::UnitX();
};
WallTouch touch(const sim::Vec3& centre, double wall_radius, const sim::Vec3& x, double r) {
  const sim::Vec3 d = x - centre;
  const double dist = d.norm();
  WallTouch t;
  t.penetration = dist + r - wall_radius;
  if (dist > 0) t.normal = d / dist;
  return t;
}
}  // namespace

ServoWall::ServoWall(const ServoWallSettings& s) : settings_(s), radius_(s.initial_radius) {
  auto check = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("servo wall: ") + what);
  };
  check(s.initial_radius > 0, "initial_radius must be > 0");
  check(s.target_pressure > 0, "target_pressure must be > 0");
  check(s.max_speed > 0, "max_speed must be > 0");
  check(s.gain_fraction > 0 && s.gain_fraction < 1, "gain_fraction must be in (0, 1)");
  check(s.shear_modulus > 0, "shear_modulus must be > 0 (Hertz law)");
  check(s.poisson >= 0 && s.poisson < 0.5, "poisson must be in [0, 0.5)");
  check(s.damping_ratio >= 0 && s.damping_ratio < 1, "damping_ratio must be in [0, 1)");
}

void ServoWall::addForces(const sim::ForceInput& in, std::span<sim::Vec3> force,
                          std::span<sim::Vec3> /*torque*/) {
  const sim::ParticleState& p = in.particles;
  double normal_sum = 0.0, stiffness_sum = 0.0;
  contacts_ = 0;
  max_penetration_ = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const WallTouch t = touch(settings_.centre, radius_, p.position[i], p.radius[i]);
    if (central_acceleration_ > 0) force[i] -= p.mass[i] * central_acceleration_ * t.normal;
    if (t.penetration <= 0) continue;
    // Mirror rule (dem-models §4.2): R~ = R_ball, the ball's own G and nu.
    const double c = sim::hertzCoefficient(settings_.shear_modulus, settings_.poisson, p.radius[i]);
    const double root = std::sqrt(t.penetration);
    const double elastic = c * t.penetration * root;  // Eq 2-22 with Eq 2-2
    const double tangent = 1.5 * c * root;            // dF/d delta
    // Closing speed of the ball on the wall (half-step velocity, as the engine's dashpots).
    const double closing = p.velocity[i].dot(t.normal) - speed_;
    const double dashpot = 2.0 * settings_.damping_ratio * std::sqrt(p.mass[i] * tangent);
    const double push = std::max(0.0, elastic + dashpot * closing);  // no tension
    force[i] -= push * t.normal;
    normal_sum += push;
    stiffness_sum += tangent;
    ++contacts_;
    max_penetration_ = std::max(max_penetration_, t.penetration);
  }
  const double area = 4.0 * std::numbers::pi * radius_ * radius_;
  pressure_ = normal_sum / area;
  // v = G (p - p_target), G = alpha A / (sum k_t dt) (see the header), |v| <= max_speed.
  const double error = pressure_ - settings_.target_pressure;
  speed_ = stiffness_sum > 0 ? settings_.gain_fraction * area * error / (stiffness_sum * in.dt)
                             : -settings_.max_speed;
  speed_ = std::clamp(speed_, -settings_.max_speed, settings_.max_speed);
  radius_ += speed_ * in.dt;
}

double ServoWall::potentialEnergy(const sim::ForceInput& in) const {
  const sim::ParticleState& p = in.particles;
  double energy = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const WallTouch t = touch(settings_.centre, radius_, p.position[i], p.radius[i]);
    if (t.penetration <= 0) continue;
    const double c = sim::hertzCoefficient(settings_.shear_modulus, settings_.poisson, p.radius[i]);
    energy += 0.4 * c * std::pow(t.penetration, 2.5);  // integral of c delta^(3/2)
  }
  return energy;
}

}  // namespace rocklab::experiments::agglomerate
