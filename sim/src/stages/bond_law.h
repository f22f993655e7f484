#pragma once
// The parallel-bond law of one step (dem-models.md §8.2, Eq 2-27..2-34), written
// once over a number type: `double` for one bond, `BondPair` (two doubles in one
// SSE register, GCC's vector extension) for two bonds at once. Both paths run the
// same operations in the same order, and IEEE arithmetic rounds each lane exactly
// as it rounds a double (-ffp-contract=off keeps the compiler from fusing either),
// so a bond's result does not depend on which path took it: the stage stays
// bitwise the same on any number of threads however its bonds fall into pairs.
//
// Why two lanes: the law is about 300 floating-point operations a bond on
// 3-vectors, which a scalar loop runs one at a time (the compiler's packing of
// x and y wins a little and costs shuffles); two bonds side by side fill each
// register without a shuffle (issue 22's bond goal).
#include <cmath>
#include <numbers>

#include "rocklab/geometry/vec.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rocklab::sim::bond_law {

using BondPair = double __attribute__((vector_size(16)));
using PairMask = long __attribute__((vector_size(16)));

// --- the few operations that differ between a double and a pair of them
inline double rootOf(double x) {
  return std::sqrt(x);
}
inline BondPair rootOf(BondPair x) {
#if defined(__SSE2__)
  return _mm_sqrt_pd(x);
#else
  return BondPair{std::sqrt(x[0]), std::sqrt(x[1])};
#endif
}
inline double pick(bool m, double a, double b) {
  return m ? a : b;
}
inline BondPair pick(PairMask m, BondPair a, BondPair b) {
  return m ? a : b;
}
inline bool anyOf(bool m) {
  return m;
}
inline bool anyOf(PairMask m) {
  return (m[0] | m[1]) != 0;
}
template <class R>
R absOf(R x) {
  return pick(x < 0.0, -x, x);
}
template <class R>
R minOf(R a, R b) {  // std::min(a, b): b only when b < a
  return pick(b < a, b, a);
}
// --- lanes: a double is one bond, a pair two
template <class R>
constexpr int kLanes = 1;
template <>
constexpr int kLanes<BondPair> = 2;
/// The value of each lane from lane(0), lane(1), ...: one register built at
/// once (setting a vector's lanes one by one goes through memory).
template <class R, class F>
[[gnu::always_inline]] inline R gather(F&& lane) {
  if constexpr (kLanes<R> == 1)
    return lane(0);
  else
    return R{lane(0), lane(1)};
}
inline double laneOf(double v, int) {
  return v;
}
inline double laneOf(BondPair v, int lane) {
  return v[lane];
}
inline bool laneOf(bool m, int) {
  return m;
}
inline bool laneOf(PairMask m, int lane) {
  return m[lane] != 0;
}

/// sin and cos of the plane's spin in one step: the series, exact to round-off
/// for the tiny angles of one step, saves two trigonometric calls; a lane past it
/// takes the library's. One text for one lane and two, so both round alike.
template <class R>
void spinSinCos(R a, R& s, R& c) {
  const R a2 = a * a;
  s = a * (1.0 - a2 / 6.0);
  c = 1.0 - 0.5 * a2 * (1.0 - a2 / 12.0);
  if (!anyOf(absOf(a) >= 1e-3)) return;
  if constexpr (kLanes<R> == 1) {
    s = std::sin(a);
    c = std::cos(a);
  } else {
    for (int lane = 0; lane < kLanes<R>; ++lane) {
      if (std::abs(a[lane]) < 1e-3) continue;
      s[lane] = std::sin(a[lane]);
      c[lane] = std::cos(a[lane]);
    }
  }
}


template <class R>
struct V3 {
  R x, y, z;
};
template <class R>
V3<R> operator+(const V3<R>& a, const V3<R>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class R>
V3<R> operator-(const V3<R>& a, const V3<R>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class R>
V3<R> operator-(const V3<R>& a) {
  return {-a.x, -a.y, -a.z};
}
template <class R>
V3<R> operator*(const V3<R>& a, R s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class R>
V3<R> operator*(R s, const V3<R>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class R>
R dot(const V3<R>& a, const V3<R>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class R>
V3<R> cross(const V3<R>& a, const V3<R>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class R>
R norm(const V3<R>& a) {
  return rootOf(dot(a, a));
}
template <class R>
V3<R> pick(decltype(R{} < R{}) m, const V3<R>& a, const V3<R>& b) {
  return {pick(m, a.x, b.x), pick(m, a.y, b.y), pick(m, a.z, b.z)};
}

template <class R, class F>
[[gnu::always_inline]] inline V3<R> gather3(F&& lane) {
  return {gather<R>([&](int l) { return lane(l).x(); }),
          gather<R>([&](int l) { return lane(l).y(); }),
          gather<R>([&](int l) { return lane(l).z(); })};
}
template <class R>
geometry::Vec3 laneOf(const V3<R>& v, int lane) {
  return {laneOf(v.x, lane), laneOf(v.y, lane), laneOf(v.z, lane)};
}

/// Peak stresses on the bond's periphery (Eq 2-33, 2-34 [R]) with one division:
/// R / I = 4 / (A R), R / J = 2 / (A R) and 1 / A = R / (A R) for the disc
/// (Eq 2-36..2-38).
template <class R>
void peakStresses(R radius, R area, R normal_force, R shear_force, R twist_moment, R bend_moment,
                  R& tensile, R& shear) {
  const R per_area_radius = 1.0 / (area * radius);
  const R per_area = radius * per_area_radius;
  tensile = -normal_force * per_area + 4.0 * bend_moment * per_area_radius;  // Eq 2-33
  shear = shear_force * per_area + 2.0 * twist_moment * per_area_radius;     // Eq 2-34
}

/// One bond's state and its balls' motion at the start of the step.
template <class R>
struct BondInput {
  V3<R> xa, xb;                        // m, positions at t
  V3<R> va, vb, wa, wb;                // m/s, rad/s at t - dt/2
  R ra, rb;                            // m, the balls' radii
  V3<R> normal;                        // the unit normal of the last update
  R normal_force;                      // N
  V3<R> shear_force;                   // N
  R twist_moment;                      // N m
  V3<R> bend_moment;                   // N m
  R radius;                            // m, the bond's disc (Eq 2-35)
  R tensile_strength, shear_strength;  // Pa
};

/// The bond after the step: its new state, what it does to its balls, and
/// whether it broke (then the caller drops the forces).
template <class R>
struct BondOutput {
  V3<R> normal;
  R normal_force;
  V3<R> shear_force;
  R twist_moment;
  V3<R> bend_moment;
  V3<R> force_b, torque_a, torque_b;  // N, N m (on a: minus force_b)
  R tensile, shear;                   // Pa, the peak stresses the check used
  decltype(R{} < R{}) broke;
};

struct BondConstants {
  double kn, ks;  // Pa/m
  double h;       // s, the step
  bool combined;  // the combined failure rule
};

template <class R>
[[gnu::always_inline]] inline BondOutput<R> stepBond(const BondInput<R>& in,
                                                     const BondConstants& k) {
  BondOutput<R> out;
  const V3<R> d = in.xb - in.xa;
  const R dist = norm(d);
  const V3<R> n = pick(dist > 0.0, d * (1.0 / dist), in.normal);
  // The bond's point on the line of centres, midway through the gap or overlap.
  const V3<R> xc = in.xa + n * (in.ra + 0.5 * (dist - in.ra - in.rb));
  // Stored shear force and bending moment turn with the contact plane: its tilt
  // (n_old -> n) by Rodrigues with the unnormalised axis k (k (k.v) (1 - cos) /
  // sin^2 = k (k.v) / (1 + cos)), then its spin about n, the mean of the balls'
  // spins, then any round-off drift out of the plane removed. A normal that
  // turned over in one step has no defined tilt and is not tilted.
  const V3<R> axis = cross(in.normal, n);
  const R c = dot(in.normal, n);
  const auto tilts = c > -1.0 + 1e-12;
  const R per_one_plus_c = 1.0 / (1.0 + c);
  R sin_spin, cos_spin;
  spinSinCos(0.5 * dot(in.wa + in.wb, n) * k.h, sin_spin, cos_spin);
  const auto carry = [&](const V3<R>& v) {
    const V3<R> tilted =
        pick(tilts, c * v + cross(axis, v) + axis * (dot(axis, v) * per_one_plus_c), v);
    const V3<R> r = cos_spin * tilted + sin_spin * cross(n, tilted);
    return r - dot(r, n) * n;
  };
  // Increments (Eq 2-29..2-32): relative motion of b against a at the bond.
  const V3<R> v_rel = (in.vb + cross(in.wb, xc - in.xb)) - (in.va + cross(in.wa, xc - in.xa));
  const R v_n = dot(v_rel, n);
  const R du_n = v_n * k.h;  // > 0 when separating
  const R h = k.h + R{};     // the step in every lane
  const V3<R> du_s = (v_rel - v_n * n) * h;
  const V3<R> dtheta = (in.wb - in.wa) * h;
  const R dtheta_n = dot(dtheta, n);
  const V3<R> dtheta_s = dtheta - dtheta_n * n;
  const R r2 = in.radius * in.radius;  // the disc, Eq 2-36..2-38
  const R area = std::numbers::pi * r2;
  const R polar = 0.5 * std::numbers::pi * r2 * r2;
  const R inertia = 0.25 * std::numbers::pi * r2 * r2;
  out.normal = n;
  out.normal_force = in.normal_force - k.kn * area * du_n;                // Eq 2-29
  out.shear_force = carry(in.shear_force) - (k.ks * area) * du_s;         // Eq 2-30 [R]
  out.twist_moment = in.twist_moment - k.ks * polar * dtheta_n;           // Eq 2-31 [R]
  out.bend_moment = carry(in.bend_moment) - (k.kn * inertia) * dtheta_s;  // Eq 2-32
  // Each force or moment against its own capacity. The combined rule adds the
  // parts, so it takes only the pull of the normal force.
  const R pulling = k.combined ? minOf(out.normal_force, R{}) : out.normal_force;
  peakStresses(in.radius, area, pulling, norm(out.shear_force), absOf(out.twist_moment),
               norm(out.bend_moment), out.tensile, out.shear);
  // No division where no bond breaks: for a positive strength,
  // stress / strength >= 1 holds exactly when stress >= strength.
  out.broke = k.combined ? out.tensile / in.tensile_strength + out.shear / in.shear_strength >= 1.0
                         : (out.tensile >= in.tensile_strength) | (out.shear >= in.shear_strength);
  const V3<R> f = out.normal_force * n + out.shear_force;  // on b (Eq 2-27)
  const V3<R> m = out.twist_moment * n + out.bend_moment;  // on b (Eq 2-28)
  out.force_b = f;
  out.torque_b = m + cross(xc - in.xb, f);
  out.torque_a = -m - cross(xc - in.xa, f);
  return out;
}

}  // namespace rocklab::sim::bond_law
