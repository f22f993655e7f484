// Angle of repose from side-view silhouettes: synthetic cones of known angle are
// recovered; a flat layer and empty input are refused; the base height is honoured.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "analysis/heap_analysis.h"
#include "rocklab/geometry/packing.h"

using namespace rocklab::experiments;
using rocklab::geometry::Rng;
using rocklab::geometry::Sphere;
using rocklab::geometry::Vec3;
using Catch::Contains;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// Balls of radius r filling a cone of base radius R and angle `angle_deg` standing on z = base_z, every ball
/// inside the cone. The silhouette depends on the surface balls only, so the surface is a jammed layer: random
/// sequential addition of balls tangent to the cone from inside (20 tries per ball-sized patch of its area).
/// The inside is a jittered grid (2.3 r apart, ±0.15 r jitter, a random height phase per column) at least 3 r
/// below the surface, so it never overlaps the surface layer.
std::vector<Sphere> coneHeap(double angle_deg, double R, double r, double base_z, std::uint64_t seed) {
  Rng rng(seed);
  const double t = std::tan(angle_deg * kDeg), c = std::cos(angle_deg * kDeg), H = R * t;
  auto depth = [&](const Vec3& p) { return (H - t * std::hypot(p.x(), p.y()) - p.z()) * c; };  // below the surface
  std::vector<Sphere> balls;
  // Surface layer: a point uniform on the lateral surface (area ∝ ρ dρ), moved r inward along the normal.
  const auto tries = static_cast<int>(20 * (std::numbers::pi * R * R / c) / (std::numbers::pi * r * r));
  for (int k = 0; k < tries; ++k) {
    const double rho = R * std::sqrt(rng.uniform()), phi = rng.uniform(0.0, 2 * std::numbers::pi);
    const Vec3 outward(t * c * std::cos(phi), t * c * std::sin(phi), c);
    const Vec3 p = Vec3(rho * std::cos(phi), rho * std::sin(phi), H - t * rho) - r * outward;
    if (p.z() < r || depth(p) < r - 1e-12) continue;  // below the base, or out through the far side at the apex
    const bool free = std::none_of(balls.begin(), balls.end(),
                                   [&](const Sphere& s) { return (s.centre - p).squaredNorm() < 4 * r * r; });
    if (free) balls.push_back({p, r});
  }
  // Inside: a jittered grid.
  const double step = 2.3 * r, jitter = 0.15 * r;
  const int n = static_cast<int>(std::ceil(R / step));
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j) {
      const double x = i * step + rng.uniform(-jitter, jitter), y = j * step + rng.uniform(-jitter, jitter);
      for (double z = r + rng.uniform(0.0, step); depth({x, y, z}) >= 3 * r; z += step) balls.push_back({{x, y, z}, r});
    }
  for (Sphere& s : balls) s.centre.z() += base_z;
  return balls;
}

/// One layer of balls (a slab 2 r thick) on a jittered grid over a w × w square.
std::vector<Sphere> flatLayer(double w, double r) {
  Rng rng(7);
  std::vector<Sphere> balls;
  const double step = 2.3 * r, jitter = 0.15 * r;
  for (double x = -w / 2; x <= w / 2; x += step)
    for (double y = -w / 2; y <= w / 2; y += step)
      balls.push_back({{x + rng.uniform(-jitter, jitter), y + rng.uniform(-jitter, jitter), r}, r});
  return balls;
}

}  // namespace

TEST_CASE("cones of known angle are recovered", "[heap]") {
  // R = 0.3 m is 30 ball radii (about 800 and 1200 balls).
  const double angle = GENERATE(26.0, 35.0);
  const std::uint64_t seed = GENERATE(1, 2, 3);
  const auto balls = coneHeap(angle, 0.3, 0.01, 0.0, seed);
  const HeapAngle a = angleOfRepose(balls, 0.0, 0.004);
  REQUIRE(a.flank_deg.size() == 4);
  INFO("cone " << angle << " deg, seed " << seed << ": " << balls.size() << " balls, mean " << a.mean_deg
               << " deg, std " << a.std_deg << ", flanks " << a.flank_deg[0] << " " << a.flank_deg[1] << " "
               << a.flank_deg[2] << " " << a.flank_deg[3] << ", height " << a.height_m << ", base radius "
               << a.base_radius_m);
  CHECK(a.balls == balls.size());
  CHECK(std::abs(a.mean_deg - angle) < 1.5);
  CHECK(a.std_deg < 1.0);
  for (double f : a.flank_deg) CHECK(std::abs(f - angle) < 2.0);
  // The balls sit inside the cone: the peak is a little below its apex, the toe a little inside its rim.
  const double apex = 0.3 * std::tan(angle * kDeg);
  CHECK(a.height_m < apex);
  CHECK(a.height_m > apex - 0.03);
  CHECK(a.base_radius_m == Approx(0.3).margin(0.02));
  CHECK_THAT(a.method, Contains("20 %") && Contains("80 %"));
}

// A heap only 7.5 ball radii across its base is at the limit of the method: the rounded top reaches into
// the 20–80 % band and flattens the fit (over 20 seeds: 1.0–1.3 deg low on average, 2.0 deg at worst).
TEST_CASE("a small heap of 7.5 ball radii is measured to within 3 degrees", "[heap]") {
  const double angle = GENERATE(26.0, 35.0);
  const HeapAngle a = angleOfRepose(coneHeap(angle, 0.15, 0.01, 0.0, 1), 0.0, 0.004);
  INFO("cone " << angle << " deg: mean " << a.mean_deg << " deg, std " << a.std_deg);
  CHECK(std::abs(a.mean_deg - angle) < 3.0);
}

TEST_CASE("a heap of about 5000 balls is recovered closely", "[heap]") {
  const auto balls = coneHeap(26.0, 0.55, 0.01, 0.0, 11);
  CHECK(balls.size() > 4500);
  const HeapAngle a = angleOfRepose(balls, 0.0, 0.005);
  INFO(balls.size() << " balls: mean " << a.mean_deg << " deg, std " << a.std_deg);
  CHECK(std::abs(a.mean_deg - 26.0) < 0.5);
  CHECK(a.std_deg < 0.5);
}

TEST_CASE("the base height is taken into account", "[heap]") {
  const auto low = coneHeap(30.0, 0.3, 0.01, 0.0, 5), high = coneHeap(30.0, 0.3, 0.01, 0.5, 5);
  const HeapAngle a = angleOfRepose(low, 0.0, 0.004), b = angleOfRepose(high, 0.5, 0.004);
  CHECK(b.mean_deg == Approx(a.mean_deg).epsilon(1e-9));
  CHECK(b.height_m == Approx(a.height_m).epsilon(1e-9));
  // Measured from the wrong base (0 instead of 0.5 m) the 20–80 % band falls on the rounded top: the answer
  // is wrong, or there is none.
  bool same = false;
  try {
    same = std::abs(angleOfRepose(high, 0.0, 0.004).mean_deg - a.mean_deg) < 1.0;
  } catch (const std::invalid_argument&) {
  }
  CHECK_FALSE(same);
}

// Decision: a flat layer is refused with an error, never reported as a small angle, so that a heap that did
// not form is flagged rather than recorded as a data point. Depending on the bin width its band bins are too
// few (coarse bins), lie within one ball's rounded edge (fine bins), or are the gaps between balls along the
// flat top, through which the fitted line does not rise (bins of 0.5 to 10 mm here: slopes of 0.05-2 deg).
TEST_CASE("a flat layer is refused", "[heap]") {
  const auto slab = flatLayer(0.3, 0.01);  // 20 mm thick
  for (double bin : {0.0002, 0.0005, 0.002, 0.005, 0.01, 0.03})
    CHECK_THROWS_WITH(angleOfRepose(slab, 0.0, bin), Contains("flank") && Contains("not a heap"));
}

TEST_CASE("empty input - a bad bin width - a NaN ball are refused", "[heap]") {
  CHECK_THROWS_WITH(angleOfRepose({}, 0.0, 0.005), Contains("no balls"));
  auto balls = coneHeap(30.0, 0.3, 0.01, 0.0, 5);
  CHECK_THROWS_WITH(angleOfRepose(balls, 0.0, 0.0), Contains("bin_width"));
  CHECK_THROWS_AS(angleOfRepose(balls, 0.0, -1.0), std::invalid_argument);
  CHECK_THROWS_WITH(angleOfRepose(balls, 0.0, 1e-9), Contains("10^7 bins"));
  balls[7].centre.x() = std::nan("");
  CHECK_THROWS_WITH(angleOfRepose(balls, 0.0, 0.005), Contains("ball 7"));
}
