#pragma once
// The servo-controlled spherical wall of the loose pack (experiments.md §f.4 step 1,
// dem-models.md §10): a sphere that holds the balls inside it and moves radially so
// that the mean pressure it measures approaches a target.
//
// Contact (dem-models.md §4.2, the mirror rule of sim's contact_props): a ball
// whose surface crosses the wall is pushed inward with the Hertz law of its own
// material, the wall taken as a mirror-image ball (R~ = R_ball, G~ = G, nu~ = nu) and
// the ball-wall penetration as the overlap: F = c delta^(3/2), c from Eq 2-22.
// A small normal dashpot (ratio `damping_ratio` of critical, ball mass and the
// tangent stiffness dF/d delta) takes energy out of the wall contacts; the wall is
// frictionless (no shear).
//
// Servo ([X] of dem-models §10): v_wall = gain (p_measured - p_target), clamped to
// +-max_speed, with p = sum of the normal forces / (4 pi R_w^2) (contraction < 0).
// The gain: moving the wall by v dt against the contacts as they are changes the
// wall force by sum(k_t) v dt, the pressure by sum(k_t) v dt / A (k_t the tangent
// stiffness 3/2 c sqrt(delta) of each wall contact, A = 4 pi R_w^2). With
// gain = alpha A / (sum(k_t) dt) one step corrects the fraction alpha of the
// pressure error if the balls stood still; alpha = 0.5 < 1 never overshoots (an
// explicit iteration is unstable beyond alpha = 2), and balls that give way only
// make the response smaller, i.e. slower but not unstable. The gain is recomputed
// every step from the contacts of that step (Hertz stiffens with load); without
// contacts the wall closes at max_speed.
//
// Optionally also a body force towards the centre (setCentralAcceleration).
// One thread, balls in index order: bitwise the same on any thread count.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "rocklab/sim/force_contribution.h"

namespace rocklab::experiments::agglomerate {

struct ServoWallSettings {
  sim::Vec3 centre = sim::Vec3::Zero();  // m
  double initial_radius = 0.0;           // m
  double target_pressure = 1e5;          // Pa  (the reference's 100 kPa)
  double max_speed = 0.5;                // m/s  |radial speed| limit
  double gain_fraction = 0.5;            // -  alpha above
  double shear_modulus = 0.0;            // Pa  G of the balls (Eq 2-22)
  double poisson = 0.2;                  // -   nu of the balls
  double damping_ratio = 0.05;           // -  normal dashpot of a wall contact, of critical
};

class ServoWall : public sim::ForceContribution {
 public:
  /// Throws std::invalid_argument for a radius, pressure, speed, modulus or
  /// gain fraction out of range.
  explicit ServoWall(const ServoWallSettings& settings);

  std::string name() const override { return "servo-controlled spherical wall"; }
  void addForces(const sim::ForceInput& in, std::span<sim::Vec3> force,
                 std::span<sim::Vec3> torque) override;
  /// Hertz energy of the wall contacts: 2/5 F delta each.
  double potentialEnergy(const sim::ForceInput& in) const override;

  double radius() const { return radius_; }      // m, now (after the last step's move)
  double pressure() const { return pressure_; }  // Pa, measured at the last step
  double speed() const { return speed_; }        // m/s, radial, of the last step
  std::size_t contacts() const { return contacts_; }
  /// Largest ball-wall penetration of the last step (m).
  double maxPenetration() const { return max_penetration_; }
  /// A body force pulling every ball towards the centre (m/s^2; 0 = none): the
  /// first phase of the servo pack (servo_pack.h) compacts the interior with it.
  void setCentralAcceleration(double a) { central_acceleration_ = a; }

 private:
  ServoWallSettings settings_;
  double radius_;
  double pressure_ = 0.0, speed_ = 0.0, max_penetration_ = 0.0, central_acceleration_ = 0.0;
  std::size_t contacts_ = 0;
};

}  // namespace rocklab::experiments::agglomerate
