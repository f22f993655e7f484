#include "contact_spectrum.h"

#include <algorithm>
#include <cmath>

#include "rocklab/geometry/mix64.h"

namespace rocklab::sim::detail {

namespace {

/// Fixed pseudo-random start in [-1, 1] (splitmix64): the same on every run and
/// thread count, with a component along every mode.
double startValue(std::uint64_t k) {
  const std::uint64_t z = geometry::mix64((k + 1) * geometry::kSplitmixGamma);
  return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
}

Vec3 part(const std::vector<double>& x, std::size_t body, int which) {
  const std::size_t o = 6 * body + 3 * static_cast<std::size_t>(which);
  return {x[o], x[o + 1], x[o + 2]};
}

void addPart(std::vector<double>& x, std::size_t body, int which, const Vec3& v) {
  const std::size_t o = 6 * body + 3 * static_cast<std::size_t>(which);
  x[o] += v.x();
  x[o + 1] += v.y();
  x[o + 2] += v.z();
}

/// Kinetic-energy norm x^T M x of one body's part of x.
double massNorm(const ContactNetwork& net, const NetworkBody& b, const Vec3& t, const Vec3& r) {
  const double rotation = b.clump < 0 ? r.squaredNorm() / b.inv_inertia
                                      : r.dot(net.clump_inertia[static_cast<std::size_t>(b.clump)] * r);
  return t.squaredNorm() / b.inv_mass + rotation;
}

/// M^-1 applied to one body's rotational part.
Vec3 inverseInertiaTimes(const ContactNetwork& net, const NetworkBody& b, const Vec3& torque) {
  return b.clump < 0 ? Vec3(b.inv_inertia * torque)
                     : Vec3(net.clump_inv_inertia[static_cast<std::size_t>(b.clump)] * torque);
}

Vec3 freshPart(std::uint64_t offset, std::size_t body, int which) {
  const std::uint64_t o = offset + 6 * body + 3 * static_cast<std::uint64_t>(which);
  return {startValue(o), startValue(o + 1), startValue(o + 2)};
}

}  // namespace

double stableStep(double stiffness, double damping) {
  return 4.0 / (damping + std::sqrt(damping * damping + 4.0 * stiffness));
}

void iterateSpectrum(const ContactNetwork& network, const ContactSource& contacts, double damping_weight,
                     int iterations, SpectrumEstimate& estimate) {
  const std::size_t n = network.bodies.size();
  std::vector<double>& x = estimate.vector;
  if (x.size() != 6 * n) {
    x.assign(6 * n, 0.0);
  } else {
    // Scale the kept vector to a unit M-norm before mixing (below).
    double norm = 0.0;
    for (std::size_t i = 0; i < n; ++i) norm += massNorm(network, network.bodies[i], part(x, i, 0), part(x, i, 1));
    const double scale = norm > 0 ? 1.0 / std::sqrt(norm) : 0.0;
    for (double& v : x) v *= scale;
  }
  // Mix in a little of a fresh pseudo-random vector (a different one at every
  // call): a kept vector that is exactly a mode of an earlier network (a contact
  // that slid, so had no shear spring) has no component along a mode that
  // appeared since, and power iteration alone would never find it.
  const std::uint64_t offset = 6 * n * (estimate.calls++ + 1);
  // (generated twice, for its norm and to add it, rather than stored: 48 bytes
  // a body less beside the run's state)
  double fresh = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    fresh += massNorm(network, network.bodies[i], freshPart(offset, i, 0), freshPart(offset, i, 1));
  const double weight = (x.empty() || std::all_of(x.begin(), x.end(), [](double v) { return v == 0.0; }) ? 1.0 : 0.01) /
                        std::sqrt(fresh);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] += weight * startValue(offset + k);
  estimate.eigenvalue = estimate.stiffness = estimate.damping = 0.0;
  estimate.body = -1;
  estimate.contacts = 0;
  contacts([&](const NetworkContact&) { ++estimate.contacts; });
  if (estimate.contacts == 0 || n == 0) return;
  // K x: allocated for this call only (the check runs every 1,000 steps), so
  // it does not add to the run's memory at its peak, the neighbour rebuild.
  std::vector<double> g(6 * n);
  for (int it = 0; it < iterations; ++it) {
    // x <- x / |x|_M, and the share of each body.
    double norm = 0.0, largest = -1.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double e = massNorm(network, network.bodies[i], part(x, i, 0), part(x, i, 1));
      norm += e;
      if (e > largest) {
        largest = e;
        estimate.body = static_cast<std::int32_t>(i);
      }
    }
    if (!(norm > 0)) {  // the contacts' bodies had no component: restart
      for (std::size_t k = 0; k < x.size(); ++k) x[k] = startValue(k);
      continue;
    }
    const double scale = 1.0 / std::sqrt(norm);
    for (double& v : x) v *= scale;
    // g = K x, and the Rayleigh quotient x^T K x (x is M-normalised).
    std::fill(g.begin(), g.end(), 0.0);
    double stiffness = 0.0, damping = 0.0;
    contacts([&](const NetworkContact& c) {
      const auto a = static_cast<std::size_t>(c.a);
      Vec3 du = -(part(x, a, 0) + part(x, a, 1).cross(c.lever_a));
      if (c.b >= 0) {
        const auto b = static_cast<std::size_t>(c.b);
        du += part(x, b, 0) + part(x, b, 1).cross(c.lever_b);
      }
      const double un = du.dot(c.normal);
      const Vec3 ut = du - un * c.normal;
      stiffness += c.kn * un * un + c.ks * ut.squaredNorm();
      damping += c.cn * un * un + c.cs * ut.squaredNorm();
      const double wn = c.kn + damping_weight * c.cn, wt = c.ks + damping_weight * c.cs;
      const Vec3 f = wn * un * c.normal + wt * ut;  // N per unit of x
      addPart(g, a, 0, -f);
      addPart(g, a, 1, -c.lever_a.cross(f));
      if (c.b >= 0) {
        const auto b = static_cast<std::size_t>(c.b);
        addPart(g, b, 0, f);
        addPart(g, b, 1, c.lever_b.cross(f));
      }
    });
    estimate.stiffness = stiffness;
    estimate.damping = damping;
    estimate.eigenvalue = stiffness + damping_weight * damping;
    // x <- M^-1 K x
    for (std::size_t i = 0; i < n; ++i) {
      const NetworkBody& b = network.bodies[i];
      const Vec3 t = b.inv_mass * part(g, i, 0), rot = inverseInertiaTimes(network, b, part(g, i, 1));
      for (int k = 0; k < 3; ++k) {
        x[6 * i + k] = t[k];
        x[6 * i + 3 + k] = rot[k];
      }
    }
  }
}

}  // namespace rocklab::sim::detail
