#pragma once
// Rotation of a rigid body with a full (asymmetric) inertia tensor. Internal.
//
// The leapfrog keeps the world-frame angular momentum L at half steps (Eq 2-45:
// M = dH/dt, so the kick L += M dt is exact for the torque). The drift of the
// orientation over dt with L fixed is the torque-free rotation, integrated by
// the symmetric splitting of the kinetic energy H = sum_k pi_k^2 / (2 I_k) into
// rotations about the principal axes (1/2, 1/2, 1, 1/2, 1/2 of dt about axes
// x, y, z, y, x), as in the NO_SQUISH integrator of Miller et al. (2002). Each
// sub-rotation is exact, so |L| is conserved to round-off and the scheme is
// time-reversible and symplectic: the energy error stays bounded (O(dt^2))
// instead of drifting, which is what the torque-free tumbling test checks. The
// gyroscopic term of Euler's equations (Eq 2-47) is carried by the splitting.
#include <cmath>

#include "rocklab/geometry/vec.h"

namespace rocklab::sim::detail {

using geometry::Quat;
using geometry::Vec3;

/// World angular velocity of a body with orientation q (body -> world),
/// principal moments `inertia` and world angular momentum L.
inline Vec3 angularVelocity(const Quat& q, const Vec3& inertia, const Vec3& L) {
  const Vec3 body_momentum = q.conjugate() * L;
  return q * body_momentum.cwiseQuotient(inertia);
}

/// World angular momentum for a world angular velocity (Eq 2-47: H = I w).
inline Vec3 angularMomentum(const Quat& q, const Vec3& inertia, const Vec3& omega) {
  const Vec3 body_omega = q.conjugate() * omega;
  return q * body_omega.cwiseProduct(inertia);
}

/// Rotates q over `dt` as a free body with world angular momentum L.
inline void rotateFree(Quat& q, const Vec3& inertia, const Vec3& L, double dt) {
  Vec3 pi = q.conjugate() * L;  // body-frame angular momentum
  auto about = [&](int axis, double tau) {
    // The flow of pi_k^2 / (2 I_k): spin about body axis k at rate pi_k / I_k;
    // the body-frame momentum turns the other way so that L = R pi is fixed.
    const double angle = tau * pi[axis] / inertia[axis];
    const double c = std::cos(0.5 * angle), s = std::sin(0.5 * angle);
    Vec3 v = Vec3::Zero();
    v[axis] = s;
    q = q * Quat(c, v.x(), v.y(), v.z());
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const double ca = std::cos(angle), sa = std::sin(angle);
    const double pa = pi[a], pb = pi[b];
    pi[a] = ca * pa + sa * pb;
    pi[b] = -sa * pa + ca * pb;
  };
  about(0, 0.5 * dt);
  about(1, 0.5 * dt);
  about(2, dt);
  about(1, 0.5 * dt);
  about(0, 0.5 * dt);
  q.normalize();
}

}  // namespace rocklab::sim::detail
