#include "agglomerate/loose_pack.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "rocklab/geometry/random_pack.h"

namespace rocklab::experiments::agglomerate {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::size_t countForFraction(double solid_fraction, double container, double radius) {
  const double ratio = container / radius;
  return std::max<std::size_t>(
      1, static_cast<std::size_t>(std::lround(solid_fraction * ratio * ratio * ratio)));
}

LoosePack geometricPack(const LoosePackParams& p, double R) {
  const auto t0 = Clock::now();
  const double r = p.servo.radius;
  LoosePack pack;
  pack.count = p.first_count > 0 ? p.first_count : countForFraction(kGeometricSolidFraction, R, r);
  geometry::RandomPackResult g = geometry::relaxedRandomPack(pack.count, r, R, p.seed);
  pack.spheres = std::move(g.spheres);
  pack.container_radius = R;
  pack.wall_time_s = since(t0);
  pack.trials.push_back({pack.count, R, static_cast<std::uint64_t>(g.sweeps), pack.wall_time_s});
  return pack;
}

LoosePack servoPack(const LoosePackParams& p, double R) {
  const auto t0 = Clock::now();
  const double band = kRadiusBand * R;
  std::size_t count =
      p.first_count > 0 ? p.first_count : countForFraction(kServoSolidFraction, R, p.servo.radius);
  std::optional<ServoPackResult> best;
  std::vector<PackTrial> trials;
  // The better of two packs: one that fits (R_w <= R) and is larger; else the smaller.
  auto better = [&](const ServoPackResult& a, const ServoPackResult& b) {
    const bool fits_a = a.wall_radius <= R, fits_b = b.wall_radius <= R;
    if (fits_a != fits_b) return fits_a;
    return fits_a ? a.wall_radius > b.wall_radius : a.wall_radius < b.wall_radius;
  };
  for (int trial = 0; trial < kMaxCountTrials; ++trial) {
    ServoPackParams sp = p.servo;
    sp.count = count;
    sp.seed = p.seed;
    ServoPackResult r = servoCompactedPack(sp);
    trials.push_back({count, r.wall_radius, r.steps, r.wall_time_s});
    const bool accepted = r.wall_radius <= R && r.wall_radius >= R - band;
    const double scale = (R - 0.5 * band) / r.wall_radius;
    if (!best || better(r, *best)) best = std::move(r);
    if (accepted) break;
    std::size_t next = static_cast<std::size_t>(std::lround(count * scale * scale * scale));
    if (next == count) next = scale > 1 ? count + 1 : count - 1;
    if (next < 1) break;
    if (std::any_of(trials.begin(), trials.end(),
                    [&](const PackTrial& t) { return t.count == next; }))
      break;  // the count oscillates between two neighbours: keep the better
    count = next;
  }
  LoosePack pack;
  pack.count = best->spheres.size();
  pack.spheres = std::move(best->spheres);
  pack.container_radius = best->wall_radius;
  pack.pressure = best->pressure;
  pack.steps = best->steps;
  pack.dt = best->dt;
  pack.trials = std::move(trials);
  pack.wall_time_s = since(t0);
  return pack;
}

}  // namespace

PackKind parsePackKind(const std::string& name) {
  if (name == "servo") return PackKind::Servo;
  if (name == "geometric") return PackKind::Geometric;
  throw std::invalid_argument("unknown pack '" + name + "' (allowed: servo, geometric)");
}

const char* packKindName(PackKind kind) {
  return kind == PackKind::Servo ? "servo" : "geometric";
}

LoosePack loosePackForDiameter(const LoosePackParams& p) {
  const double R = 0.5 * p.diameter;
  if (!(p.servo.radius > 0)) throw std::invalid_argument("loose pack: r_max must be > 0");
  if (!(R >= p.servo.radius))
    throw std::invalid_argument("loose pack: the diameter must be at least 2 r_max");
  return p.kind == PackKind::Servo ? servoPack(p, R) : geometricPack(p, R);
}

}  // namespace rocklab::experiments::agglomerate
