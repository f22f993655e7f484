#include "rocklab/geometry/random_pack.h"

#include <algorithm>
#include <cmath>

#include "parameter_check.h"
#include "rocklab/geometry/bond_pairs.h"

namespace rocklab::geometry {

namespace {

constexpr double kSkin = 0.3;        // neighbour-list reach beyond contact, × r
constexpr double kConverged = 1e-6;  // overlap tolerance, × r

Vec3 uniformInBall(Rng& rng, double radius) {
  for (;;) {
    const Vec3 p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (p.squaredNorm() <= 1) return radius * p;
  }
}

}  // namespace

RandomPackResult relaxedRandomPack(std::size_t count, double radius, double container_radius,
                                   std::uint64_t seed, int max_sweeps) {
  detail::requireParameter(radius > 0 && std::isfinite(radius), "relaxedRandomPack", "radius",
                           radius, "must be > 0 (m)");
  detail::requireParameter(container_radius >= radius && std::isfinite(container_radius),
                           "relaxedRandomPack", "container_radius", container_radius,
                           "must be >= the sphere radius (" + detail::formatValue(radius) + " m)");
  RandomPackResult out;
  Rng rng(seed);
  const double reach = container_radius - radius;  // centres stay within it
  out.spheres.reserve(count);
  for (std::size_t i = 0; i < count; ++i)
    out.spheres.push_back({uniformInBall(rng, reach), radius});
  std::vector<Sphere>& s = out.spheres;
  std::vector<SpherePair> pairs;
  std::vector<Vec3> built_at;
  for (out.sweeps = 0; out.sweeps < max_sweeps; ++out.sweeps) {
    bool rebuild = pairs.empty() && count > 1;
    for (std::size_t i = 0; i < built_at.size() && !rebuild; ++i)
      rebuild = (s[i].centre - built_at[i]).norm() > 0.5 * kSkin * radius;
    if (rebuild) {
      pairs = bondPairs(s, kSkin);  // the bond-gap rule with the skin as gap: pairs within reach
      built_at.clear();
      for (const Sphere& b : s) built_at.push_back(b.centre);
    }
    double worst = 0;
    for (const auto& [i, j] : pairs) {
      const Vec3 d = s[j].centre - s[i].centre;
      const double dist = d.norm();
      const double overlap = 2 * radius - dist;
      if (!(overlap > kConverged * radius)) continue;
      worst = std::max(worst, overlap);
      // Coincident centres (vanishingly rare): separate along x.
      const Vec3 n = dist > 0 ? Vec3(d / dist) : Vec3::UnitX();
      s[i].centre -= 0.5 * overlap * n;
      s[j].centre += 0.5 * overlap * n;
    }
    for (Sphere& b : s) {
      const double excess = b.centre.norm() - reach;
      if (!(excess > kConverged * radius)) continue;
      worst = std::max(worst, excess);
      b.centre *= reach / b.centre.norm();
    }
    out.max_overlap = worst;
    if (worst == 0) break;
  }
  return out;
}

}  // namespace rocklab::geometry
