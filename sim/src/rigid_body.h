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

/// World angular velocity of a body with rotation R (body -> world), principal
/// moments `inertia` and world angular momentum L.
inline Vec3 angularVelocity(const geometry::Mat3& R, const Vec3& inertia, const Vec3& L) {
  return R * (R.transpose() * L).cwiseQuotient(inertia);
}
/// The same for an orientation q.
inline Vec3 angularVelocity(const Quat& q, const Vec3& inertia, const Vec3& L) {
  return angularVelocity(q.toRotationMatrix(), inertia, L);
}

/// World angular momentum for a world angular velocity (Eq 2-47: H = I w).
inline Vec3 angularMomentum(const Quat& q, const Vec3& inertia, const Vec3& omega) {
  const Vec3 body_omega = q.conjugate() * omega;
  return q * body_omega.cwiseProduct(inertia);
}

/// sin and cos of x. A step turns a body by omega dt, about 1e-4 rad, where the
/// series below (to x^9 and x^10) is exact to round-off: its first omitted term
/// is below 3e-18 of the result up to |x| = 0.1. libm's sin and cos, ten calls a
/// body a step, took a fifth of a clump scene's time; larger angles still use them.
[[gnu::always_inline]] inline void sinCos(double x, double& s, double& c) {
  const double ax = std::abs(x);
  if (ax <= 1e-3) {  // the usual case: to x^5 and x^4 (first omitted term < 2e-21 relative)
    const double x2 = x * x;
    s = x * (1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120)));
    c = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24));
  } else if (ax <= 0.1) {
    const double x2 = x * x;
    s = x * (1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880)))));
    c = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24 + x2 * (-1.0 / 720 + x2 * (1.0 / 40320 + x2 * (-1.0 / 3628800)))));
  } else {
    s = std::sin(x);
    c = std::cos(x);
  }
}

/// Rotates B bodies over `dt` as free bodies with world angular momenta L[l]:
/// q[l] in place. Each body's arithmetic is exactly that of B = 1 (so results do
/// not depend on how bodies are batched); the B chains of dependent operations are
/// interleaved, a sub-rotation of every body before the next, so that the core
/// overlaps them: one body's chain alone leaves it waiting on each result.
template <int B>
[[gnu::always_inline]] inline void rotateFreeBatch(Quat* q, const Vec3* inertia, const Vec3* L, double dt) {
  double qw[B], qx[B], qy[B], qz[B], pi[3][B], rate[3][B];
  for (int l = 0; l < B; ++l) {
    const Vec3 body = q[l].conjugate() * L[l];  // body-frame angular momentum
    for (int a = 0; a < 3; ++a) {
      pi[a][l] = body[a];
      rate[a][l] = 1.0 / inertia[l][a];  // the divisions out of the chain of sub-rotations
    }
    qw[l] = q[l].w();
    qx[l] = q[l].x();
    qy[l] = q[l].y();
    qz[l] = q[l].z();
  }
  auto about = [&](const int axis, const double tau) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int l = 0; l < B; ++l) {
      // The flow of pi_k^2 / (2 I_k): spin about body axis k at rate pi_k / I_k;
      // the body-frame momentum turns the other way so that L = R pi is fixed.
      const double angle = tau * pi[axis][l] * rate[axis][l];
      double s, c;
      sinCos(0.5 * angle, s, c);
      // q = q * (c, s e_k), written out: the right factor has one vector component.
      const double w = qw[l], x = qx[l], y = qy[l], z = qz[l];
      switch (axis) {
        case 0: qw[l] = w * c - x * s; qx[l] = w * s + x * c; qy[l] = y * c + z * s; qz[l] = z * c - y * s; break;
        case 1: qw[l] = w * c - y * s; qx[l] = x * c - z * s; qy[l] = w * s + y * c; qz[l] = z * c + x * s; break;
        default: qw[l] = w * c - z * s; qx[l] = x * c + y * s; qy[l] = y * c - x * s; qz[l] = w * s + z * c; break;
      }
      const double ca = 1.0 - 2.0 * s * s, sa = 2.0 * s * c;  // the full angle's, from the half's
      const double pa = pi[a][l], pb = pi[b][l];
      pi[a][l] = ca * pa + sa * pb;
      pi[b][l] = -sa * pa + ca * pb;
    }
  };
  about(0, 0.5 * dt);
  about(1, 0.5 * dt);
  about(2, dt);
  about(1, 0.5 * dt);
  about(0, 0.5 * dt);
  for (int l = 0; l < B; ++l) {
    q[l] = Quat(qw[l], qx[l], qy[l], qz[l]);
    q[l].normalize();
  }
}

/// Rotates q over `dt` as a free body with world angular momentum L.
inline void rotateFree(Quat& q, const Vec3& inertia, const Vec3& L, double dt) { rotateFreeBatch<1>(&q, &inertia, &L, dt); }

}  // namespace rocklab::sim::detail
